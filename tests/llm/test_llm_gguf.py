"""The real bundled GGUF (SmolLM2-135M) through the llamacpp backend: mechanics, not content quality."""

from __future__ import annotations

import time

import pytest
from typer.testing import CliRunner

from anomalygen.schema import TaskProposal

pytest.importorskip("llama_cpp")


@pytest.mark.slow
@pytest.mark.gguf
def test_llamacpp_cli_ask_returns_schema_valid_task_proposal(tmp_path, monkeypatch):
    from anomalygen.llm.backends.llamacpp_backend import bundled_model_path
    from anomalygen.llm.cli import app

    assert bundled_model_path().suffix == ".gguf"
    monkeypatch.setenv("ANOMALYGEN_LLM__CACHE_PATH", str(tmp_path / "cache.sqlite"))
    args = ["ask", "--backend", "llamacpp", "--schema", "TaskProposal", "--seed", "0"]
    args.append("A knife lies on the edge of a kitchen counter")
    start = time.perf_counter()
    result = CliRunner().invoke(app, args)
    first_s = time.perf_counter() - start
    assert result.exit_code == 0, result.output
    proposal = TaskProposal.model_validate_json(result.stdout)
    assert isinstance(proposal.scenario.room, str) and proposal.provenance.engine in ("knowledge", "llm")
    assert "llamacpp:SmolLM2-135M-Instruct" in result.stderr
    assert first_s < 300  # generous: a loaded 2-core CI box; ~10-25 s when quiet

    # same request again: served from the cache, identical object, no model call
    again = CliRunner().invoke(app, args)
    assert again.exit_code == 0, again.output
    assert TaskProposal.model_validate_json(again.stdout) == proposal
    assert "requests=0" in again.stderr and "1hit" in again.stderr
