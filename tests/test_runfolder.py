"""Run folder: atomic writes, validated reads, per-item errors, resume after a SIGKILL."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from anomalygen.config import load_settings
from anomalygen.errors import ItemFailed, UserError
from anomalygen.runfolder import (
    RunFolder,
    atomic_write_text,
    read_jsonl,
    read_model,
    try_read_model,
    write_jsonl,
    write_model,
)
from anomalygen.runner import run_items
from anomalygen.schema import Hypothesis, ItemError

HERE = Path(__file__).parent


def _hyp(i):
    return Hypothesis(rank=1, problem=f"p{i}", solution="s", target_object=f"o{i}")


def test_atomic_write_leaves_no_temp_files_and_replaces_whole(tmp_path):
    target = tmp_path / "a" / "f.txt"
    atomic_write_text(target, "first")
    atomic_write_text(target, "second")
    assert target.read_text() == "second"
    assert [p.name for p in target.parent.iterdir()] == ["f.txt"]


def test_failed_write_keeps_the_old_file(tmp_path, monkeypatch):
    target = tmp_path / "f.json"
    write_model(target, _hyp(1))

    def boom(*a, **k):
        raise OSError("disk full")

    monkeypatch.setattr(os, "replace", boom)
    with pytest.raises(OSError):
        write_model(target, _hyp(2))
    monkeypatch.undo()
    assert read_model(target, Hypothesis).problem == "p1"
    assert list(tmp_path.iterdir()) == [target]


def test_read_model_reports_invalid_and_missing_files(tmp_path):
    with pytest.raises(UserError, match="missing file"):
        read_model(tmp_path / "nope.json", Hypothesis)
    bad = tmp_path / "bad.json"
    bad.write_text('{"rank": 0, "problem": "p", "solution": "s", "target_object": "o", "extra": 1}')
    with pytest.raises(UserError, match="unknown field 'extra'"):
        read_model(bad, Hypothesis)
    assert try_read_model(bad, Hypothesis) is None


def test_jsonl_round_trip_and_line_numbered_errors(tmp_path):
    path = tmp_path / "h.jsonl"
    write_jsonl(path, [_hyp(i) for i in range(3)])
    assert [h.problem for h in read_jsonl(path, Hypothesis)] == ["p0", "p1", "p2"]
    path.write_text(path.read_text() + '{"rank": "first"}\n')
    with pytest.raises(UserError, match="line 4"):
        read_jsonl(path, Hypothesis)
    assert len(read_jsonl(path, Hypothesis, strict=False)) == 3


def test_jsonl_keeps_a_record_whole_across_a_unicode_line_separator(tmp_path):
    path = tmp_path / "h.jsonl"
    write_jsonl(path, [Hypothesis(rank=1, problem="a\u2028b", solution="s", target_object="o")])
    [back] = read_jsonl(path, Hypothesis)  # pydantic writes U+2028 raw; str.splitlines would cut there
    assert back.problem == "a\u2028b"


def test_jsonl_that_is_not_text_or_one_bad_line_is_one_line(tmp_path):
    path = tmp_path / "h.jsonl"
    path.write_bytes('{"problem": "caf\u00e9"}\n'.encode("latin-1"))
    with pytest.raises(UserError, match=r"line 1: not UTF-8 text .*save the JSONL file as UTF-8"):
        read_jsonl(path, Hypothesis, strict=False)
    path.write_text("# a comment\n")
    with pytest.raises(UserError) as info:
        read_jsonl(path, Hypothesis)
    assert "\n" not in str(info.value) and f"{path}, line 1: not a valid Hypothesis" in str(info.value)


def test_a_file_given_as_the_run_folder_is_a_user_error(tmp_path):
    path = tmp_path / "notes.txt"
    path.write_text("x")
    for opening in (RunFolder.open, RunFolder.create):
        with pytest.raises(UserError, match="a file, not a run folder"):
            opening(path)
    with pytest.raises(UserError, match="cannot create the run folder: not a directory"):
        RunFolder.create(path / "run")


def test_open_missing_run_folder_is_a_user_error(tmp_path):
    with pytest.raises(UserError, match="run folder not found"):
        RunFolder.open(tmp_path / "missing")


def test_manifest_records_config_seed_and_stage_timings(tmp_path):
    settings = load_settings(overrides={"seed": 3, "quiet": True, "workers": 1})
    run = RunFolder.create(tmp_path / "r", settings=settings)
    run_items(run, "demo", [("a", 1)], _write_item, settings=settings)
    m = run.load_manifest()
    assert m.seed == 3 and m.config["seed"] == 3
    assert m.stages["demo"].done == 1 and m.stages["demo"].wall_s >= 0
    assert m.package_version


def _write_item(item_id, payload, ctx):
    if payload == "fail":
        raise ItemFailed(f"{item_id} cannot be built: no support")
    if payload == "crash":
        raise ZeroDivisionError("unexpected")
    write_model(ctx.run.root / "items" / f"{item_id}.json", _hyp(item_id))
    return item_id


@pytest.mark.parametrize("workers", [1, 2])
def test_one_failing_item_never_ends_the_batch(tmp_path, workers):
    settings = load_settings(overrides={"quiet": True, "workers": workers})
    run = RunFolder.create(tmp_path / "r")
    items = [("a", 1), ("b", "fail"), ("c", "crash"), ("d", 1)]
    summary = run_items(run, "demo", items, _write_item, settings=settings)
    assert (summary.done, summary.failed) == (2, 2)
    assert summary.errors["b"] == "b cannot be built: no support"
    assert summary.errors["c"].startswith("ZeroDivisionError: unexpected")
    assert {e.item_id for e in run.errors("demo")} == {"b", "c"}
    assert isinstance(read_model(run.error_path("demo", "b"), ItemError), ItemError)


def test_resume_skips_done_items_and_force_redoes_them(tmp_path):
    settings = load_settings(overrides={"quiet": True, "workers": 1})
    run = RunFolder.create(tmp_path / "r")
    items = [("a", 1), ("b", 1)]
    done = lambda i: (run.root / "items" / f"{i}.json").exists()  # noqa: E731
    assert run_items(run, "demo", items, _write_item, settings=settings, is_done=done).done == 2
    again = run_items(run, "demo", items, _write_item, settings=settings, is_done=done)
    assert (again.done, again.skipped) == (0, 2)
    forced = run_items(run, "demo", items, _write_item, settings=settings, is_done=done, force=True)
    assert (forced.done, forced.skipped) == (2, 0)


def test_a_fixed_error_is_cleared_on_the_next_run(tmp_path):
    settings = load_settings(overrides={"quiet": True, "workers": 1})
    run = RunFolder.create(tmp_path / "r")
    run_items(run, "demo", [("a", "fail")], _write_item, settings=settings)
    assert run.errors("demo")
    run_items(run, "demo", [("a", 1)], _write_item, settings=settings)
    assert not run.errors("demo")


@pytest.mark.slow
def test_killed_stage_resumes_with_every_item_present_exactly_once(tmp_path):
    root, n = tmp_path / "run", 12
    cmd = [sys.executable, str(HERE / "_resume_worker.py"), str(root), str(n), "0.15"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.time() + 60
    while time.time() < deadline:
        items = root / "items"
        if items.is_dir() and len(list(items.glob("item*.json"))) >= 4:
            break
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    before = {p.stem for p in (root / "items").glob("item*.json")}
    assert 4 <= len(before) < n, "the kill should land mid-stage"
    for p in (root / "items").glob("item*.json"):  # nothing visible is half-written
        assert read_model(p, Hypothesis).problem == p.stem

    out = subprocess.run(cmd, capture_output=True, text=True, timeout=120, check=True)
    assert f"{n - len(before)} done, {len(before)} skipped" in out.stdout
    files = sorted(p.stem for p in (root / "items").glob("item*.json"))
    assert files == [f"item{i:03d}" for i in range(n)]
    assert not list(root.rglob(".*.tmp")), "stale temp files are swept on resume"
    # Items finished before the kill were not executed again.
    log = (root / "log.txt").read_text().split()
    assert sorted(set(log)) == files
    assert all(log.count(i) == 1 for i in before)


def _report_key(item_id, payload, ctx):
    return ctx.settings.llm.api_key.get_secret_value()


@pytest.mark.parametrize("workers", [1, 2])
def test_item_functions_see_the_real_secret_not_a_masked_copy(tmp_path, workers):
    settings = load_settings(overrides={"quiet": True, "workers": workers, "llm.api_key": "sk-real"})
    run = RunFolder.create(tmp_path / "r", settings=settings)
    summary = run_items(run, "demo", [("a", 0), ("b", 0)], _report_key, settings=settings)
    assert summary.results == {"a": "sk-real", "b": "sk-real"}
    assert "sk-real" not in run.manifest_path.read_text()
