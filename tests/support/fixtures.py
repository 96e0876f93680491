"""Pytest fixtures around the scripted LLM server.

Import the fixture into a test module (pytest puts ``tests/`` on ``sys.path`` because
``tests/conftest.py`` sits in a folder without ``__init__.py``)::

    from support.fixtures import scripted_server  # noqa: F401
    from support.openai_server import text, status

    def test_x(scripted_server):
        srv = scripted_server([text('{"a": 1}')])
        cfg = llm_config_for(srv, tmp_path)   # or build LLMConfig(base_url=srv.base_url, ...) yourself
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from support.openai_server import Responder, ScriptedOpenAIServer


@pytest.fixture
def scripted_server() -> Iterator[Callable[..., ScriptedOpenAIServer]]:
    """A factory: ``scripted_server(responder)`` starts a server that stops at the end of the test."""
    started: list[ScriptedOpenAIServer] = []

    def start(responder: Responder, **kwargs) -> ScriptedOpenAIServer:
        srv = ScriptedOpenAIServer(responder, **kwargs).__enter__()
        started.append(srv)
        return srv

    yield start
    for srv in started:
        srv.__exit__(None, None, None)


def llm_config_for(srv: ScriptedOpenAIServer, tmp_path: Path, **overrides):
    """An ``LLMConfig`` pointing the openai backend at ``srv`` with a per-test cache and fast timeouts."""
    from anomalygen.config import LLMConfig

    values = {
        "backend": "openai",
        "model": "scripted-model",
        "base_url": srv.base_url,
        "api_key": "sk-test-not-a-real-key",
        "cache_path": str(tmp_path / "llm-cache.sqlite"),
        "timeout_s": 5.0,
        "http_retries": 2,
        "repair_retries": 2,
    }
    values.update(overrides)
    return LLMConfig(**values)
