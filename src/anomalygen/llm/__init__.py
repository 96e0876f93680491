"""The LLM layer: one validated, cached, retried interface over OpenAI-compatible, Anthropic and
in-process llama.cpp backends.

    from anomalygen.llm import get_client, LLMItemError
    client = get_client(settings.llm)
    proposal = client.complete(messages, schema=TaskProposal)   # a validated TaskProposal

SDKs are imported only when a backend is built, so importing this package is cheap.
"""

from __future__ import annotations

from anomalygen.llm.client import LLMClient, LLMItemError, parse_reply
from anomalygen.llm.factory import get_client, make_backend, shared_client
from anomalygen.llm.usage import record_usage

__all__ = [
    "LLMClient",
    "LLMItemError",
    "get_client",
    "make_backend",
    "parse_reply",
    "record_usage",
    "shared_client",
]
