"""The LLM layer: one validated, cached, retried interface over OpenAI-compatible, Anthropic and
in-process llama.cpp backends.

    from anomalygen.llm import get_client, LLMItemError
    client = get_client(settings.llm)
    proposal = client.complete(messages, schema=TaskProposal)   # a validated TaskProposal

Names are resolved lazily (PEP 562) so that ``anomalygen --help``, which imports ``anomalygen.llm.cli``,
does not pay for numpy, pydantic models or any SDK.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

_EXPORTS = {
    "LLMClient": "anomalygen.llm.client",
    "LLMItemError": "anomalygen.llm.client",
    "parse_reply": "anomalygen.llm.client",
    "get_client": "anomalygen.llm.factory",
    "make_backend": "anomalygen.llm.backends.registry",
    "shared_client": "anomalygen.llm.factory",
    "record_usage": "anomalygen.llm.usage",
}

__all__ = [
    "LLMClient",
    "LLMItemError",
    "get_client",
    "make_backend",
    "parse_reply",
    "record_usage",
    "shared_client",
]

if TYPE_CHECKING:  # pragma: no cover
    from anomalygen.llm.backends.registry import make_backend
    from anomalygen.llm.client import LLMClient, LLMItemError, parse_reply
    from anomalygen.llm.factory import get_client, shared_client
    from anomalygen.llm.usage import record_usage


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'anomalygen.llm' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(list(globals()) + list(_EXPORTS))
