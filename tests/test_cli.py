"""CLI behaviour a user sees: one-line errors and non-zero exit codes, never a traceback."""

import json

import pytest

from support.bad_files import BAD_FILES, make_bad_file, one_error_line, run_cli, snapshot


def test_schema_prints_json_schema_and_rejects_unknown_names():
    ok = run_cli("schema", "TaskProposal")
    assert ok.returncode == 0
    schema = json.loads(ok.stdout)
    assert schema["additionalProperties"] is False
    assert {"name", "hazard_class", "scenario", "provenance"} <= set(schema["properties"])
    one_error_line(run_cli("schema", "Nope"))


def test_missing_run_folder(tmp_path):
    one_error_line(run_cli("detect", "--run", str(tmp_path / "missing")))


def test_invalid_config_value_from_env(tmp_path):
    result = run_cli("config", "show", env={"ANOMALYGEN_DETECT__K": "many"})
    one_error_line(result)
    assert "detect.k" in result.stderr


def test_unreadable_and_missing_config_files(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_bytes(b"\xff\xfe\x00garbage")
    one_error_line(run_cli("config", "show", "--config", str(bad)))
    one_error_line(run_cli("config", "show", "--config", str(tmp_path / "none.toml")))


def test_config_show_masks_secrets_and_reflects_precedence(tmp_path):
    cfg = tmp_path / "c.toml"
    cfg.write_text('seed = 4\n[llm]\nbackend = "openai"\nmodel = "toml-model"\n')
    result = run_cli("config", "show", "--json", "--config", str(cfg),
                 env={"ANOMALYGEN_LLM__API_KEY": "sk-secret-123", "ANOMALYGEN_LLM__MODEL": "env-model"})
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert data["seed"] == 4 and data["llm"]["model"] == "env-model" and data["llm"]["api_key"] == "***"
    assert "sk-secret-123" not in result.stdout + result.stderr


@pytest.mark.parametrize("args", [["brainstorm", "--n", "many"], ["no-such-command"]])
def test_usage_errors_exit_non_zero_without_traceback(args):
    result = run_cli(*args)
    assert result.returncode == 2
    assert "Traceback" not in result.stderr


def test_error_text_with_brackets_is_printed_verbatim_on_one_line(tmp_path):
    bad = tmp_path / "b.toml"
    bad.write_text("[llm]\nbackend = [1, 2]\n" + "# padding " * 20)
    result = run_cli("config", "show", "--config", str(bad), env={"COLUMNS": "60"})
    one_error_line(result)
    assert len(result.stderr.strip().splitlines()) == 1
    assert "llm.backend" in result.stderr


CONFIG_LONG_LINE = "Expected '=' after a key in a key/value pair (at line 1, column 100001)"


@pytest.mark.parametrize("kind", sorted(BAD_FILES))
def test_a_bad_config_file_is_one_line_and_no_run_folder(tmp_path, kind):
    path, words = make_bad_file(tmp_path, kind)
    line = one_error_line(run_cli("config", "show", "--config", path))
    assert str(path) in line
    assert (CONFIG_LONG_LINE if kind == "long_line" else words) in line, line
    run = tmp_path / "run"
    assert one_error_line(run_cli("brainstorm", "--run", run, "--quiet", "--config", path)) == line
    assert not run.exists()


def test_an_empty_or_comment_only_config_file_is_the_defaults(tmp_path):
    for text in ("", "# nothing set yet\n\n"):
        path = tmp_path / "c.toml"
        path.write_text(text)
        result = run_cli("config", "show", "--json", "--config", path)
        assert result.returncode == 0, result.stderr
        assert json.loads(result.stdout)["seed"] == json.loads(run_cli("config", "show", "--json").stdout)["seed"]


def test_a_bad_tasks_text_named_in_the_config_or_the_environment_leaves_no_run_folder(tmp_path):
    latin1, words = make_bad_file(tmp_path, "latin1")
    cfg = tmp_path / "c.toml"
    cfg.write_text(f'[brainstorm]\ntasks_text = "{latin1}"\n')
    run = tmp_path / "run"
    assert words in one_error_line(run_cli("run", "--run", run, "--config", cfg, "--quiet"))
    folder, words = make_bad_file(tmp_path, "folder")
    line = one_error_line(run_cli("brainstorm", "--run", run, "--quiet", env={"ANOMALYGEN_BRAINSTORM__TASKS_TEXT": str(folder)}))
    assert f"{folder}: a folder, not a --tasks-text file" in line
    assert snapshot(run) == {} and not run.exists()


def test_a_file_given_as_the_run_folder_is_one_line(tmp_path):
    path = tmp_path / "notes.txt"
    path.write_text("mine\n")
    for command in ("brainstorm", "detect"):
        line = one_error_line(run_cli(command, "--run", path, "--quiet"))
        assert f"{path}: a file, not a run folder" in line
    assert "cannot create the run folder: not a directory" in one_error_line(run_cli("brainstorm", "--run", path / "r"))
    assert path.read_text() == "mine\n"


def test_a_folder_as_the_png_to_write_is_one_line_before_any_rendering(tmp_path):
    for args in (["assets", "render", "Mug"], ["assets", "gallery"]):
        line = one_error_line(run_cli(*args, "--out", tmp_path))
        assert f"{tmp_path}: a folder; give --out the PNG file's path" in line
    assert list(tmp_path.iterdir()) == []
