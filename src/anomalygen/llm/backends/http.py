"""What the HTTP backends (OpenAI-compatible, Anthropic) share: the model and API key checks, where
errors say they tried to connect, short error text, and image types."""

from __future__ import annotations

import os

from anomalygen.errors import UserError


class HTTPBackend:
    """The model must be set; the API key comes from the config, else ``env_var``, and may be missing
    only for a custom ``base_url`` (a local server)."""

    def __init__(self, config, env_var: str, *, no_model: str, no_key: str):
        if not config.model:
            raise UserError(f"llm.model is not set: {no_model}")
        key = config.api_key.get_secret_value() if config.api_key else os.environ.get(env_var)
        if not key and not config.base_url:
            raise UserError(no_key)
        self.model = config.model
        self._where = origin(config.base_url) if config.base_url else "the default endpoint"
        self.api_key_in_use = key  # only so the client can scrub it from error text
        self.supports_images = bool(config.vision)


def image_mime(data: bytes) -> str:
    if data[:8] == b"\x89PNG\r\n\x1a\n":
        return "image/png"
    if data[:3] == b"\xff\xd8\xff":
        return "image/jpeg"
    if data[:4] == b"RIFF" and data[8:12] == b"WEBP":
        return "image/webp"
    return "application/octet-stream"


def short_error(exc: Exception) -> str:
    body = getattr(exc, "body", None)
    msg = None
    if isinstance(body, dict):
        err = body.get("error", body)
        msg = err.get("message") if isinstance(err, dict) else str(err)
    text = str(msg or getattr(exc, "message", None) or exc)
    return " ".join(text.split())[:200]


def origin(url: str) -> str:
    """scheme://host:port of an endpoint, for error messages (no path, no user:password)."""
    from urllib.parse import urlsplit

    parts = urlsplit(url)
    host = parts.hostname or "?"
    return f"{parts.scheme}://{host}" + (f":{parts.port}" if parts.port else "")
