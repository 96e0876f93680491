"""The one LLM interface every stage uses: ``complete(messages, schema=...)`` → validated object.

Why a client around the backends: the backends only move bytes. Everything that makes LLM output safe
to build on lives here, once: the schema instruction, JSON extraction, pydantic validation, the repair
conversation (the validation error goes back to the model), the reply cache, HTTP retry with
exponential backoff, the concurrency bound, and usage/cost accounting. A reply that never validates
ends as ``LLMItemError`` (an ``ItemFailed``), so the runner fails that item and the batch goes on.
"""

from __future__ import annotations

import hashlib
import json
import logging
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np
from pydantic import BaseModel, ValidationError
from pydantic_core import PydanticSerializationError

from anomalygen.errors import ItemFailed, UserError
from anomalygen.llm.backends import Backend, PermanentError, RawReply, Request, TransientError
from anomalygen.llm.backends.registry import make_backend
from anomalygen.llm.cache import ReplyCache, cache_key
from anomalygen.llm.jsonextract import JSONExtractError, extract_json
from anomalygen.llm.schema_tools import bounded_schema, response_schema, schema_fingerprint
from anomalygen.schema import LLMUsage, format_validation_error

log = logging.getLogger("anomalygen.llm")

MAX_ECHO_CHARS = 2000  # how much of a bad reply is echoed back in a repair turn
MAX_ERROR_CHARS = 300


class LLMItemError(ItemFailed):
    """This request could not produce a valid reply (repairs or HTTP retries exhausted). One line."""


def _one_line(text: str, limit: int = MAX_ERROR_CHARS) -> str:
    flat = " ".join(str(text).split())
    return flat if len(flat) <= limit else flat[: limit - 3] + "..."


def schema_instruction(schema: type[BaseModel], schema_json: dict[str, Any]) -> str:
    return (
        f"Answer with exactly one JSON object for a {schema.__name__}, valid against this JSON schema. "
        "Output only the JSON object: no prose, no code fences, no fields the schema does not define.\n"
        f"JSON schema: {json.dumps(schema_json, separators=(',', ':'))}"
    )


def repair_instruction(schema: type[BaseModel], error: str) -> str:
    return (
        f"Your previous reply could not be used: {error}. "
        f"Reply again with only the corrected JSON object for {schema.__name__}."
    )


def with_system(messages: list[dict[str, Any]], instruction: str) -> list[dict[str, Any]]:
    """Prepend the instruction to the first system message (many chat templates allow only one)."""
    out = [dict(m) for m in messages]
    if out and out[0].get("role") == "system":
        out[0]["content"] = f"{out[0].get('content', '')}\n\n{instruction}".strip()
    else:
        out.insert(0, {"role": "system", "content": instruction})
    return out


class LLMClient:
    """Validated, cached, retried, accounted completions over one backend. Thread-safe."""

    def __init__(
        self,
        config,
        backend: Backend,
        *,
        rng: np.random.Generator | None = None,
        backoff_base_s: float = 0.5,
        backoff_max_s: float = 20.0,
        sleep: Callable[[float], None] = time.sleep,
    ):
        self.config = config
        self.backend = backend
        self.usage = LLMUsage()
        self._rng = rng
        self._backoff_base_s = backoff_base_s
        self._backoff_max_s = backoff_max_s
        self._sleep = sleep
        self._lock = threading.Lock()
        self._slots = threading.BoundedSemaphore(config.concurrency)
        self._cache = ReplyCache(config.cache_path) if config.cache else None
        secret = config.api_key.get_secret_value() if config.api_key else None
        # scrub the configured key and one the backend took from the environment (OPENAI_API_KEY, ...)
        self._secrets = [s for s in {secret, getattr(backend, "api_key_in_use", None)} if s and len(s) >= 4]

    # ------------------------------------------------------------------ public API
    @property
    def backend_name(self) -> str:
        return self.backend.name

    @property
    def model(self) -> str:
        return self.backend.model

    @property
    def supports_images(self) -> bool:
        return bool(getattr(self.backend, "supports_images", False))

    def complete(
        self,
        messages: list[dict[str, Any]],
        *,
        schema: type[BaseModel] | None = None,
        temperature: float | None = None,
        seed: int | None = None,
        max_tokens: int | None = None,
        images: list[bytes] | None = None,
        cache: bool | None = None,
    ) -> str | BaseModel:
        """One completion: the reply text, or with ``schema`` a validated instance (repaired if needed)."""
        _check_messages(messages)
        if images and not self.supports_images:
            raise UserError(
                f"the configured LLM ({self.backend.name}) does not take images; use a vision endpoint and set llm.vision = true"
            )
        temp = self.config.temperature if temperature is None else float(temperature)
        limit = self.config.max_tokens if max_tokens is None else int(max_tokens)
        use_cache = self.config.cache if cache is None else (cache and self._cache is not None)
        if schema is None:
            req = Request(list(messages), None, None, temp, seed, limit, images)
            return self._request(req, None, use_cache).text
        if getattr(self.backend, "prompt_schema_style", "full") == "bounded":
            schema_json = bounded_schema(
                schema,
                max_string=getattr(self.backend, "max_string", 100),
                max_items=getattr(self.backend, "max_items", 3),
                required_only=False,
            )
        else:
            schema_json = response_schema(schema)
        conversation = with_system(list(messages), schema_instruction(schema, schema_json))
        attempts = self.config.repair_retries + 1
        last_error = ""
        pending: list[tuple[str, RawReply]] = []  # cached only if the conversation ends valid
        for attempt in range(attempts):
            req = Request(conversation, schema.__name__, schema_json, temp, seed, limit, images)
            raw = self._request(req, schema, use_cache, pending)
            try:
                result = parse_reply(raw.text, schema)
            except ReplyInvalid as exc:
                last_error = str(exc)
                if raw.completion_tokens >= limit:  # cut off, not wrong: say so rather than hide it
                    last_error = f"reply truncated at max_tokens={limit}; {last_error}"
            else:
                self._store(pending)
                return result
            if attempt + 1 < attempts:
                with self._lock:
                    self.usage.retries += 1
                conversation = conversation + [
                    {"role": "assistant", "content": raw.text[:MAX_ECHO_CHARS]},
                    {"role": "user", "content": repair_instruction(schema, last_error)},
                ]
        raise LLMItemError(
            self._scrub(
                f"LLM reply is not a valid {schema.__name__} after {attempts} attempt(s): {_one_line(last_error)}"
            )
        )

    def complete_many(
        self, batch: Sequence[list[dict[str, Any]]], *, schema: type[BaseModel] | None = None, **kwargs: Any
    ) -> list[str | BaseModel | LLMItemError]:
        """Many independent completions, at most ``config.concurrency`` in flight; failures stay per item."""

        def one(messages: list[dict[str, Any]]) -> str | BaseModel | LLMItemError:
            try:
                return self.complete(messages, schema=schema, **kwargs)
            except LLMItemError as exc:
                return exc

        if not batch:
            return []
        workers = max(1, min(self.config.concurrency, len(batch)))
        with ThreadPoolExecutor(max_workers=workers, thread_name_prefix="llm") as pool:
            return list(pool.map(one, batch))

    def reset_usage(self) -> LLMUsage:
        """Return the usage so far and start counting afresh (for per-stage accounting)."""
        with self._lock:
            taken, self.usage = self.usage, LLMUsage()
        return taken

    def __reduce__(self):
        """Pickle as "rebuild from config" so a client can travel to spawn-pool workers (usage starts at 0)."""
        return (_rebuild_client, (self.config, self._rng, self._backoff_base_s, self._backoff_max_s))

    # ------------------------------------------------------------------ internals
    def _request(
        self,
        req: Request,
        schema: type[BaseModel] | None,
        use_cache: bool,
        pending: list[tuple[str, RawReply]] | None = None,
    ) -> RawReply:
        """One reply, from the cache or the backend. With ``pending`` the cache write is deferred.

        Why defer: a repair conversation is replayed from the cache only if it ended in a valid object;
        an item that failed is asked afresh on the next run rather than frozen into its failure.
        """
        key = None
        if use_cache and self._cache is not None:
            key = cache_key(
                {
                    "backend": self.backend.name,
                    "model": self.backend.model,
                    "messages": req.messages,
                    "schema": schema_fingerprint(schema),
                    "temperature": req.temperature,
                    "seed": req.seed,
                    "max_tokens": req.max_tokens,
                    "images": [hashlib.sha256(i).hexdigest() for i in (req.images or [])],
                }
            )
            hit = self._cache.get(key)
            with self._lock:
                if hit is not None:
                    self.usage.cache_hits += 1
                else:
                    self.usage.cache_misses += 1
            if hit is not None:
                return RawReply(*hit)
        raw = self._call_with_retries(req)
        if key is not None:
            if pending is None:
                self._store([(key, raw)])
            else:
                pending.append((key, raw))
        return raw

    def _store(self, entries: list[tuple[str, RawReply]]) -> None:
        if self._cache is not None:
            for key, raw in entries:
                self._cache.put(key, raw.text, raw.prompt_tokens, raw.completion_tokens)

    def _call_with_retries(self, req: Request) -> RawReply:
        attempts = self.config.http_retries + 1
        for attempt in range(attempts):
            try:
                with self._slots:
                    raw = self.backend.complete_raw(req)
            except TransientError as exc:
                if attempt + 1 >= attempts:
                    log.debug(
                        self._scrub(f"{self.backend.name}: giving up after {attempts} attempt(s): {exc}")
                    )
                    raise LLMItemError(
                        self._scrub(
                            f"{self.backend.name} request failed after {attempts} attempt(s): {_one_line(str(exc))}"
                        )
                    ) from None
                with self._lock:
                    self.usage.retries += 1
                delay = self._backoff(attempt)
                log.info(
                    self._scrub(
                        f"{self.backend.name}: {exc}; retry {attempt + 1}/{attempts - 1} in {delay:.2f}s"
                    )
                )
                self._sleep(delay)
                continue
            except PermanentError as exc:
                raise LLMItemError(
                    self._scrub(f"{self.backend.name} request failed: {_one_line(str(exc))}")
                ) from None
            self._account(raw, req.max_tokens)
            return raw
        raise AssertionError("unreachable")  # pragma: no cover

    def _backoff(self, attempt: int) -> float:
        delay = min(self._backoff_max_s, self._backoff_base_s * (2**attempt))
        if self._rng is not None:
            with self._lock:  # a Generator is not thread-safe
                delay *= 1.0 + 0.25 * float(self._rng.random())
        return delay

    def _account(self, raw: RawReply, max_tokens: int | None = None) -> None:
        cost = None
        p_in, p_out = self.config.price_prompt_per_mtok, self.config.price_completion_per_mtok
        if p_in is not None or p_out is not None:
            cost = (raw.prompt_tokens * (p_in or 0.0) + raw.completion_tokens * (p_out or 0.0)) / 1e6
        with self._lock:
            self.usage.requests += 1
            self.usage.prompt_tokens += raw.prompt_tokens
            self.usage.completion_tokens += raw.completion_tokens
            if max_tokens is not None and raw.completion_tokens >= max_tokens:
                self.usage.truncated += 1
            if cost is not None:
                self.usage.cost_usd = (self.usage.cost_usd or 0.0) + cost

    def _scrub(self, text: str) -> str:
        for secret in self._secrets:
            text = text.replace(secret, "***")
        return text


def _rebuild_client(config, rng, backoff_base_s, backoff_max_s) -> LLMClient:
    return LLMClient(
        config, make_backend(config), rng=rng, backoff_base_s=backoff_base_s, backoff_max_s=backoff_max_s
    )


class ReplyInvalid(ValueError):
    """A reply that is not valid JSON for the schema; the message is fed back to the model."""


def parse_reply(text: str, schema: type[BaseModel]) -> BaseModel:
    """Extract and validate; every failure mode of untrusted text becomes ``ReplyInvalid``."""
    try:
        value = extract_json(text)
    except JSONExtractError as exc:
        raise ReplyInvalid(str(exc)) from None
    if not isinstance(value, dict):
        raise ReplyInvalid(f"expected a JSON object, got a JSON {type(value).__name__}")
    try:
        model = schema.model_validate(value)
    except ValidationError as exc:
        raise ReplyInvalid(format_validation_error(exc)) from None
    except (ValueError, TypeError, RecursionError) as exc:  # validators of odd inputs
        raise ReplyInvalid(f"invalid value: {_one_line(str(exc), 200)}") from None
    try:  # it must be storable as an artefact: JSON escapes can smuggle in lone surrogates
        model.model_dump_json()
    except (PydanticSerializationError, UnicodeError, ValueError):
        raise ReplyInvalid(
            "the reply contains text that is not valid Unicode (e.g. a lone surrogate escape)"
        ) from None
    return model


def _check_messages(messages: Any) -> None:
    if not isinstance(messages, list) or not messages:
        raise TypeError("messages must be a non-empty list of {'role', 'content'} dicts")
    for m in messages:
        if not isinstance(m, dict) or "role" not in m or "content" not in m:
            raise TypeError("each message must be a dict with 'role' and 'content'")
