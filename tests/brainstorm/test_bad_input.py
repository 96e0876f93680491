"""Bad user files for ``brainstorm --tasks-text`` and ``--tasks``, through the real CLI: one line on
stderr naming the file (and the line where one applies) and what to do, exit code 2, no traceback,
and the run folder as it was (not created when new; byte for byte the same when it exists)."""

from __future__ import annotations

import pytest

from anomalygen.brainstorm.free_text import MAX_LINE_CHARS
from support.bad_files import BAD_FILES, make_bad_file, one_error_line, run_cli, snapshot

OPTIONS = ("--tasks-text", "--tasks")
# what each option says of a line too long: a hazard line has a limit, a tasks.jsonl line is just not JSON
LONG_LINE = {"--tasks-text": f"100,000 characters, more than the {MAX_LINE_CHARS:,} a line of the --tasks-text file",
             "--tasks": "not a valid TaskProposal"}
NO_TASKS = {"--tasks-text": "no task descriptions, only blank lines and # comments; write one hazard per line",
            "--tasks": "no tasks in the --tasks file, only blank lines; write one TaskProposal per line"}


def brainstorm(run, option, path):
    return run_cli("brainstorm", "--run", run, "--engine", "knowledge", "--quiet", option, path)


@pytest.mark.parametrize("option", OPTIONS)
@pytest.mark.parametrize("kind", sorted(BAD_FILES))
def test_a_bad_file_is_one_line_and_no_run_folder(tmp_path, option, kind):
    path, words = make_bad_file(tmp_path, kind)
    run = tmp_path / "run"
    line = one_error_line(brainstorm(run, option, path))
    assert line.startswith(f"error: {path}")
    assert words in line and (LONG_LINE[option] in line if kind == "long_line" else True), line
    if (kind, option) != ("long_line", "--tasks"):  # that one is a JSON error at a line of the path named
        assert f"{option} file" in line  # says which of the user's files it is
    assert not run.exists()


@pytest.mark.parametrize("option", OPTIONS)
@pytest.mark.parametrize("content", ["", "\n   \n\n"])
def test_a_file_with_no_tasks_is_one_line_and_no_run_folder(tmp_path, option, content):
    path = tmp_path / "empty.txt"
    path.write_text(content)
    run = tmp_path / "run"
    assert NO_TASKS[option] in one_error_line(brainstorm(run, option, path))
    assert not run.exists()


def test_comment_lines_alone_are_no_tasks_and_a_comment_is_no_json(tmp_path):
    path = tmp_path / "comments.txt"
    path.write_text("# my hazards\n\n# (to write)\n")
    assert NO_TASKS["--tasks-text"] in one_error_line(brainstorm(tmp_path / "run", "--tasks-text", path))
    path.write_text("\n# one task per line, as JSON\n")
    line = one_error_line(brainstorm(tmp_path / "run", "--tasks", path))
    assert f"{path}, line 2: not a valid TaskProposal" in line and "anomalygen schema TaskProposal" in line
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("option", OPTIONS)
def test_an_existing_run_folder_is_left_byte_for_byte(tmp_path, option):
    run = tmp_path / "run"
    run.mkdir()
    (run / "manifest.json").write_text('{"name": "run"}\n')
    (run / "tasks.jsonl").write_text("the earlier tasks\n")
    before = snapshot(run)
    path, _ = make_bad_file(tmp_path, "latin1")
    one_error_line(brainstorm(run, option, path))
    assert snapshot(run) == before
