"""The real bundled GGUF (SmolLM2-135M) through the llamacpp backend: mechanics, not content quality."""

from __future__ import annotations

import time

import pytest
from typer.testing import CliRunner

from anomalygen.schema import Scenario


@pytest.mark.slow
@pytest.mark.gguf
def test_llamacpp_cli_ask_returns_a_schema_valid_object(tmp_path, monkeypatch):
    """The CLI's ask path end to end on the real model: schema instruction, grammar, validation, cache.
    The nested ``Scenario`` record keeps the reply short: a whole TaskProposal is within the 135M model's
    grammar but not reliably within a bounded token budget (the grammar itself is checked for every
    artefact below)."""
    from anomalygen.llm.backends.llamacpp_backend import bundled_model_path
    from anomalygen.llm.cli import app

    assert bundled_model_path().suffix == ".gguf"
    monkeypatch.setenv("ANOMALYGEN_LLM__CACHE_PATH", str(tmp_path / "cache.sqlite"))
    # a bounded budget: with the defaults (3 repairs of up to 1,024 tokens) a loaded 2-core box can spend 15 minutes
    monkeypatch.setenv("ANOMALYGEN_LLM__MAX_TOKENS", "1024")
    monkeypatch.setenv("ANOMALYGEN_LLM__REPAIR_RETRIES", "1")
    args = ["ask", "--backend", "llamacpp", "--schema", "Scenario", "--seed", "0"]
    args.append("A knife lies on the edge of a kitchen counter")
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    scenario = Scenario.model_validate_json(result.stdout)
    assert isinstance(scenario.room, str) and isinstance(scenario.co_objects, list)
    assert "llamacpp:SmolLM2-135M-Instruct" in result.stderr

    # same request again: served from the cache, identical object, no model call
    again = CliRunner().invoke(app, args)
    assert again.exit_code == 0, again.output
    assert Scenario.model_validate_json(again.stdout) == scenario
    assert "requests=0" in again.stderr and "1hit" in again.stderr


# --------------------------------------------------------------------------- the server child process

FILLER = " ".join(f"Item {i}: a cup, a knife and a cable lie on the kitchen floor." for i in range(40))


@pytest.fixture(scope="module")
def gguf_backend():
    from anomalygen.config import LLMConfig
    from anomalygen.llm.backends.llamacpp_backend import LlamaCppBackend

    backend = LlamaCppBackend(LLMConfig(backend="llamacpp", cache=False, n_ctx=2048))
    yield backend
    backend.close()


@pytest.mark.slow
@pytest.mark.gguf
def test_every_artefact_schema_constrains_the_real_server(gguf_backend):
    """llama.cpp builds a grammar from each bounded artefact schema and the first tokens obey it."""
    from anomalygen.llm.backends import Request
    from anomalygen.llm.schema_tools import bounded_schema
    from anomalygen.schema import ARTEFACTS

    for name, model in sorted(ARTEFACTS.items()):
        schema = bounded_schema(model, max_string=80, max_items=2, required_only=False)
        msgs = [{"role": "user", "content": f"Write a {name} as JSON."}]
        reply = gguf_backend.complete_raw(Request(msgs, name, schema, 0.0, 0, 12))
        assert reply.text.lstrip().startswith("{"), (name, reply.text)
        assert reply.completion_tokens > 0


@pytest.mark.slow
@pytest.mark.gguf
def test_a_server_killed_mid_request_fails_one_item_and_the_batch_goes_on(gguf_backend):
    """A native crash (here SIGKILL while the prompt is evaluated) ends one item with a clear line; the
    next request starts a fresh server and answers."""
    import os
    import signal
    import threading

    from anomalygen.config import LLMConfig
    from anomalygen.llm import LLMItemError
    from anomalygen.llm.client import LLMClient

    config = LLMConfig(backend="llamacpp", cache=False, concurrency=1, max_tokens=24, http_retries=2)
    client = LLMClient(config, gguf_backend, backoff_base_s=0.01)
    server = gguf_backend.server
    server.ensure_running()
    starts_before, pid = server.starts, server.pid
    log_offset = server._log_path.stat().st_size  # earlier tests' requests are in the log already

    def kill_when_busy():
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            with open(server._log_path, "rb") as log:
                log.seek(log_offset)
                if b"processing task" in log.read():
                    os.kill(pid, signal.SIGKILL)
                    return
            time.sleep(0.005)

    killer = threading.Thread(target=kill_when_busy)
    killer.start()
    batch = [
        [{"role": "user", "content": FILLER + " Which item is the most dangerous?"}],
        [{"role": "user", "content": "Name one kitchen hazard."}],
        [{"role": "user", "content": "Name one bathroom hazard."}],
    ]
    results = client.complete_many(batch, seed=0)
    killer.join()
    assert isinstance(results[0], LLMItemError)
    message = str(results[0])
    assert "crashed during this request (killed by SIGKILL)" in message and "\n" not in message
    assert all(isinstance(r, str) and r.strip() for r in results[1:]), results
    assert server.starts == starts_before + 1 and server.pid != pid and server.running
    assert client.usage.requests == 2


def test_a_model_file_that_cannot_load_fails_the_item_with_the_servers_words(tmp_path):
    from anomalygen.config import LLMConfig
    from anomalygen.llm import LLMItemError, get_client

    bad = tmp_path / "broken.gguf"
    bad.write_bytes(b"GGUF" + b"\0" * 64)
    client = get_client(LLMConfig(backend="llamacpp", model_path=str(bad), cache=False, http_retries=0))
    with pytest.raises(LLMItemError, match=r"the llama.cpp server for broken.gguf did not start \(exited"):
        client.complete([{"role": "user", "content": "hi"}])
    client.backend.close()
