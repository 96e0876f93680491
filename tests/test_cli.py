"""CLI behaviour a user sees: one-line errors and non-zero exit codes, never a traceback."""

import json
import os
import subprocess
import sys

import pytest


def cli(*args, env=None, cwd=None):
    full_env = {**os.environ, **(env or {})}
    return subprocess.run(
        [sys.executable, "-m", "anomalygen.cli", *args], capture_output=True, text=True, env=full_env, cwd=cwd, timeout=120
    )


def _one_line_error(result, code=2):
    assert result.returncode == code, result.stderr
    assert "Traceback" not in result.stderr
    assert result.stderr.strip().startswith("error:")


def test_schema_prints_json_schema_and_rejects_unknown_names():
    ok = cli("schema", "TaskProposal")
    assert ok.returncode == 0
    schema = json.loads(ok.stdout)
    assert schema["additionalProperties"] is False
    assert {"name", "hazard_class", "scenario", "provenance"} <= set(schema["properties"])
    _one_line_error(cli("schema", "Nope"))


def test_missing_run_folder(tmp_path):
    _one_line_error(cli("detect", "--run", str(tmp_path / "missing")))


def test_invalid_config_value_from_env(tmp_path):
    result = cli("config", "show", env={"ANOMALYGEN_DETECT__K": "many"})
    _one_line_error(result)
    assert "detect.k" in result.stderr


def test_unreadable_and_missing_config_files(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_bytes(b"\xff\xfe\x00garbage")
    _one_line_error(cli("config", "show", "--config", str(bad)))
    _one_line_error(cli("config", "show", "--config", str(tmp_path / "none.toml")))


def test_config_show_masks_secrets_and_reflects_precedence(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text('seed = 4\n[llm]\nbackend = "openai"\nmodel = "toml-model"\n')
    result = cli("config", "show", "--json", "--config", str(cfg),
                 env={"ANOMALYGEN_LLM__API_KEY": "sk-secret-123", "ANOMALYGEN_LLM__MODEL": "env-model"})
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["seed"] == 4 and data["llm"]["model"] == "env-model" and data["llm"]["api_key"] == "***"
    assert "sk-secret-123" not in result.stdout + result.stderr


@pytest.mark.parametrize("args", [["brainstorm", "--n", "many"], ["no-such-command"]])
def test_usage_errors_exit_non_zero_without_traceback(args):
    result = cli(*args)
    assert result.returncode == 2
    assert "Traceback" not in result.stderr


def test_error_text_with_brackets_is_printed_verbatim_on_one_line(tmp_path):
    bad = tmp_path / "b.toml"
    bad.write_text("[llm]\nbackend = [1, 2]\n" + "# padding " * 20)
    result = cli("config", "show", "--config", str(bad), env={"COLUMNS": "60"})
    _one_line_error(result)
    assert len(result.stderr.strip().splitlines()) == 1
    assert "llm.backend" in result.stderr
