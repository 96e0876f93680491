"""Any OpenAI-compatible endpoint (OpenAI, vLLM, Ollama, llama.cpp server, LM Studio) via the SDK.

Structured output degrades gracefully: ``json_schema`` response format first; a server that answers
400 to it gets ``json_object`` (JSON mode) instead; one that rejects that too gets a plain request.
The weaker mode is remembered only once it has worked, so a 400 for another reason (say, a prompt
too long) does not downgrade later requests.
The schema is also in the prompt, and the client validates every reply, so each level is safe.
The SDK's own retries are off: ``anomalygen.llm.client`` owns retry, backoff and their counting.
"""

from __future__ import annotations

import base64
import threading
from typing import Any

from anomalygen.llm.backends import PermanentError, RawReply, Request, TransientError
from anomalygen.llm.backends.http import HTTPBackend, image_mime, short_error

_MODES = ("json_schema", "json_object", "plain")


def with_images_openai(messages: list[dict[str, Any]], images: list[bytes]) -> list[dict[str, Any]]:
    """Attach images as data-URI parts to the last user message (the vision chat format)."""
    out = [dict(m) for m in messages]
    for msg in reversed(out):
        if msg.get("role") == "user":
            parts: list[dict[str, Any]] = [{"type": "text", "text": str(msg.get("content", ""))}]
            for img in images:
                b64 = base64.b64encode(img).decode("ascii")
                parts.append(
                    {"type": "image_url", "image_url": {"url": f"data:{image_mime(img)};base64,{b64}"}}
                )
            msg["content"] = parts
            break
    return out


class OpenAIBackend(HTTPBackend):
    name = "openai"
    prompt_schema_style = "full"

    def __init__(self, config):
        import openai

        super().__init__(
            config,
            "OPENAI_API_KEY",
            no_model="pass --model NAME or set ANOMALYGEN_LLM__MODEL",
            no_key="no OpenAI API key: set OPENAI_API_KEY or ANOMALYGEN_LLM__API_KEY (or --base-url for a local server)",
        )
        self._openai = openai
        self._client = openai.OpenAI(
            api_key=self.api_key_in_use or "not-needed", base_url=config.base_url, timeout=config.timeout_s, max_retries=0
        )
        self._mode_index = 0
        self._limit_param = "max_tokens"  # local servers know it; OpenAI's newer models want max_completion_tokens  # moves down _MODES when a server rejects a structured-output mode
        self._lock = threading.Lock()

    @property
    def structured_mode(self) -> str:
        return _MODES[self._mode_index]

    def complete_raw(self, request: Request) -> RawReply:
        messages = request.messages
        if request.images:
            messages = with_images_openai(messages, request.images)
        structured = request.schema_json is not None
        index = self._mode_index if structured else len(_MODES) - 1
        while True:
            mode = _MODES[index]
            kwargs: dict[str, Any] = {
                "model": self.model,
                "messages": messages,
                "temperature": request.temperature,
                self._limit_param: request.max_tokens,
            }
            if request.seed is not None:
                kwargs["seed"] = request.seed
            if mode == "json_schema":
                kwargs["response_format"] = {
                    "type": "json_schema",
                    "json_schema": {
                        "name": request.schema_name or "reply",
                        "schema": request.schema_json,
                        "strict": False,
                    },
                }
            elif mode == "json_object":
                kwargs["response_format"] = {"type": "json_object"}
            try:
                resp = self._client.chat.completions.create(**kwargs)
            except self._openai.BadRequestError as exc:
                if "max_completion_tokens" in short_error(exc) and self._limit_param == "max_tokens":
                    self._limit_param = "max_completion_tokens"  # newer OpenAI models reject max_tokens
                    continue
                if index + 1 < len(_MODES):  # maybe the server lacks this structured-output mode
                    index += 1
                    continue
                raise PermanentError(f"HTTP 400 bad request: {short_error(exc)}") from None
            except (self._openai.RateLimitError, self._openai.InternalServerError) as exc:
                raise TransientError(f"HTTP {exc.status_code}: {short_error(exc)}") from None
            except self._openai.APITimeoutError:
                raise TransientError("request timed out") from None
            except self._openai.APIConnectionError as exc:
                raise TransientError(f"cannot connect to {self._where}: {type(exc).__name__}") from None
            except self._openai.APIStatusError as exc:
                if exc.status_code in (408, 409) or exc.status_code >= 500:
                    raise TransientError(f"HTTP {exc.status_code}: {short_error(exc)}") from None
                raise PermanentError(f"HTTP {exc.status_code}: {short_error(exc)}") from None
            if structured and index > self._mode_index:
                with self._lock:  # a weaker mode worked where a stronger one got 400: remember it
                    self._mode_index = max(self._mode_index, index)
            choices = getattr(resp, "choices", None) or []
            text = (choices[0].message.content if choices and choices[0].message else None) or ""
            usage = getattr(resp, "usage", None)
            return RawReply(
                text=text,
                prompt_tokens=int(getattr(usage, "prompt_tokens", 0) or 0),
                completion_tokens=int(getattr(usage, "completion_tokens", 0) or 0),
            )

    def ping(self) -> str:
        """List models (cheap, no tokens); returns the first model id the server reports."""
        try:
            models = self._client.models.list()
            first = next(iter(models), None)
        except self._openai.APIError as exc:
            raise PermanentError(f"{type(exc).__name__}: {short_error(exc)}") from None
        return first.id if first is not None else ""
