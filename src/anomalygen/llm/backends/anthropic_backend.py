"""Anthropic Messages API via the official SDK; structured output through a forced tool call.

Why tool use: the API has no JSON mode, but a tool whose ``input_schema`` is our schema, forced with
``tool_choice``, makes the model emit the object as the tool's input. System messages move to the
``system`` parameter, which is where the API wants them.
"""

from __future__ import annotations

import base64
import inspect
import json
from typing import Any

from anomalygen.llm.backends import PermanentError, RawReply, Request, TransientError
from anomalygen.llm.backends.http import HTTPBackend, image_mime, short_error


def split_system(messages: list[dict[str, Any]]) -> tuple[str, list[dict[str, Any]]]:
    system = "\n\n".join(str(m.get("content", "")) for m in messages if m.get("role") == "system")
    rest = [
        {"role": m["role"], "content": m.get("content", "")} for m in messages if m.get("role") != "system"
    ]
    return system, rest


class AnthropicBackend(HTTPBackend):
    name = "anthropic"
    prompt_schema_style = "full"

    def __init__(self, config):
        import anthropic

        super().__init__(
            config,
            "ANTHROPIC_API_KEY",
            no_model="pass --model NAME (e.g. an Anthropic model id)",
            no_key="no Anthropic API key: set ANTHROPIC_API_KEY or ANOMALYGEN_LLM__API_KEY",
        )
        base = config.base_url.rstrip("/") if config.base_url else None
        if base and base.endswith("/v1"):
            base = base[: -len("/v1")]  # the SDK appends /v1/messages itself
        self._anthropic = anthropic
        # Recent SDKs dropped sampling parameters from ``messages.create``; send them only where accepted.
        self._accepts_temperature = (
            "temperature" in inspect.signature(anthropic.resources.messages.Messages.create).parameters
        )
        self._client = anthropic.Anthropic(
            api_key=self.api_key_in_use or "not-needed", base_url=base, timeout=config.timeout_s, max_retries=0
        )

    def complete_raw(self, request: Request) -> RawReply:
        system, messages = split_system(request.messages)
        if request.images:
            messages = _with_images(messages, request.images)
        kwargs: dict[str, Any] = {
            "model": self.model,
            "messages": messages,
            "max_tokens": request.max_tokens,
        }
        if self._accepts_temperature:
            kwargs["temperature"] = min(request.temperature, 1.0)
        if system:
            kwargs["system"] = system
        tool_name = None
        if request.schema_json is not None:
            tool_name = _tool_name(request.schema_name)
            kwargs["tools"] = [
                {
                    "name": tool_name,
                    "description": "Return the answer as this structured object.",
                    "input_schema": request.schema_json,
                }
            ]
            kwargs["tool_choice"] = {"type": "tool", "name": tool_name}
        a = self._anthropic
        try:
            resp = self._client.messages.create(**kwargs)
        except (a.RateLimitError, a.InternalServerError) as exc:
            raise TransientError(f"HTTP {exc.status_code}: {short_error(exc)}") from None
        except a.APITimeoutError:
            raise TransientError("request timed out") from None
        except a.APIConnectionError as exc:
            raise TransientError(f"cannot connect to {self._where}: {type(exc).__name__}") from None
        except a.APIStatusError as exc:
            if exc.status_code in (408, 409, 529) or exc.status_code >= 500:
                raise TransientError(f"HTTP {exc.status_code}: {short_error(exc)}") from None
            raise PermanentError(f"HTTP {exc.status_code}: {short_error(exc)}") from None
        text = ""
        texts = []
        for block in getattr(resp, "content", None) or []:
            kind = getattr(block, "type", None)
            if kind == "tool_use" and tool_name is not None:
                text = json.dumps(getattr(block, "input", {}), ensure_ascii=False)
                break
            if kind == "text":
                texts.append(getattr(block, "text", "") or "")
        if not text:
            text = "".join(texts)
        usage = getattr(resp, "usage", None)
        return RawReply(
            text=text,
            prompt_tokens=int(getattr(usage, "input_tokens", 0) or 0),
            completion_tokens=int(getattr(usage, "output_tokens", 0) or 0),
        )


def _tool_name(schema_name: str | None) -> str:
    name = "".join(ch if ch.isalnum() or ch in "_-" else "_" for ch in (schema_name or "reply"))
    return f"emit_{name}"[:64]


def _with_images(messages: list[dict[str, Any]], images: list[bytes]) -> list[dict[str, Any]]:
    out = [dict(m) for m in messages]
    for msg in reversed(out):
        if msg.get("role") == "user":
            parts: list[dict[str, Any]] = [
                {
                    "type": "image",
                    "source": {
                        "type": "base64",
                        "media_type": image_mime(img),
                        "data": base64.b64encode(img).decode("ascii"),
                    },
                }
                for img in images
            ]
            parts.append({"type": "text", "text": str(msg.get("content", ""))})
            msg["content"] = parts
            break
    return out
