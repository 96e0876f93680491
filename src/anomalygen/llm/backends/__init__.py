"""Backends: each turns one chat request into one raw reply (text plus token counts).

They know nothing about validation, repair or caching (``anomalygen.llm.client`` does that), so a new
backend is one small class with ``complete_raw``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol


@dataclass
class RawReply:
    text: str
    prompt_tokens: int = 0
    completion_tokens: int = 0


@dataclass
class Request:
    """One request as the client hands it to a backend (sampling values already resolved)."""

    messages: list[dict[str, Any]]
    schema_name: str | None
    schema_json: dict[str, Any] | None
    temperature: float
    seed: int | None
    max_tokens: int
    images: list[bytes] | None = None


class TransientError(Exception):
    """A failure worth retrying (429, 5xx, timeout, dropped connection)."""


class PermanentError(Exception):
    """A failure retrying will not fix (bad request, auth); its message is already key-free."""


class Backend(Protocol):
    name: str
    model: str
    supports_images: bool

    def complete_raw(self, request: Request) -> RawReply: ...
