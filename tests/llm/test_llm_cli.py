"""``anomalygen llm ping|ask`` against the scripted server (typer's CliRunner and the real entry point)."""

from __future__ import annotations

import json

import pytest
from llm_helpers import VALID, VALID_TEXT
from typer.testing import CliRunner

from anomalygen.cli import main
from anomalygen.llm.cli import app
from anomalygen.schema import Scenario
from support.openai_server import text

runner = CliRunner()


def write_config(tmp_path, srv, **extra) -> str:
    lines = [
        "[llm]",
        'backend = "openai"',
        'model = "scripted-model"',
        f'base_url = "{srv.base_url}"',
        'api_key = "sk-cli-secret-42"',
        f'cache_path = "{tmp_path / "cache.sqlite"}"',
        "http_retries = 1",
        "repair_retries = 1",
    ] + [f"{k} = {json.dumps(v)}" for k, v in extra.items()]
    path = tmp_path / "anomalygen.toml"
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def test_ask_with_schema_prints_validated_json(scripted_server, tmp_path):
    srv = scripted_server([text("Here it is: " + VALID_TEXT)])
    cfg = write_config(tmp_path, srv)
    result = runner.invoke(
        app, ["ask", "A knife on a counter", "--schema", "Scenario", "--config", cfg, "--seed", "3"]
    )
    assert result.exit_code == 0, result.output
    assert Scenario.model_validate_json(result.stdout) == Scenario(**VALID)
    body = srv.requests[0]
    assert body["messages"][-1] == {"role": "user", "content": "A knife on a counter"} and body["seed"] == 3
    assert "requests=1" in result.stderr and "sk-cli-secret-42" not in result.output


def test_ask_overrides_backend_model_and_base_url_flags(scripted_server, tmp_path):
    srv = scripted_server([text("plain answer")])
    result = runner.invoke(
        app,
        [
            "ask",
            "hello",
            "--backend",
            "openai",
            "--model",
            "other-model",
            "--base-url",
            srv.base_url,
            "--json",
            "--no-cache",
        ],
    )
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout) == {"text": "plain answer"}
    assert srv.requests[0]["model"] == "other-model"


def test_ping_reports_backend_model_latency(scripted_server, tmp_path):
    srv = scripted_server([text("pong")])
    result = runner.invoke(app, ["ping", "--config", write_config(tmp_path, srv), "--json"])
    assert result.exit_code == 0, result.output
    payload = json.loads(result.stdout)
    assert (
        payload["backend"] == "openai" and payload["model"] == "scripted-model" and payload["reply"] == "pong"
    )
    assert payload["latency_s"] >= 0 and srv.requests[0]["max_tokens"] == 8


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["llm", "ask", "hi"], "no LLM configured"),
        (
            ["llm", "ask", "hi", "--backend", "openai", "--model", "m", "--schema", "Nope"],
            "unknown schema 'Nope'",
        ),
    ],
)
def test_user_errors_are_one_line_and_exit_2(args, message, capsys):
    with pytest.raises(SystemExit) as info:
        main(args)
    assert info.value.code == 2
    err = " ".join(capsys.readouterr().err.split())  # rich wraps long lines at the console width
    assert err.startswith("error:") and message in err and "Traceback" not in err


def test_invalid_replies_end_as_one_line_error(scripted_server, tmp_path, capsys):
    srv = scripted_server([text("no json, sorry")])
    with pytest.raises(SystemExit) as info:
        main(["llm", "ask", "hi", "--schema", "Scenario", "--config", write_config(tmp_path, srv)])
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert "not a valid Scenario after 2 attempt(s)" in err and "Traceback" not in err
    assert len(srv.requests) == 2
