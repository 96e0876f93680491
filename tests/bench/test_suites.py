"""Frozen suites: built reproducibly by the pipeline's stages, a manifest that says how, a checksum of
every scene that catches a changed file, and a name that is not built yet says how to build it."""

from __future__ import annotations

import json

import pytest

from anomalygen.bench.suites import SUITES, build_suite, open_suite, suite_dir, verify_suite
from anomalygen.errors import UserError


def test_the_named_suites():
    a, o = SUITES["anomaly-111"], SUITES["outside"]
    assert (a.version, a.n, a.seed, a.engine) == (1, 111, 0, "knowledge")
    from importlib import resources
    from pathlib import Path

    shipped = [json.loads(r) for r in resources.files("anomalygen").joinpath(f"data/suites/{o.lines}")
               .read_text().splitlines()]
    outside = Path(__file__).parents[2] / "benchmarks" / "data" / "outside_hazards.jsonl"
    labelled = {r["id"]: r for r in map(json.loads, outside.read_text().splitlines())}
    assert len(shipped) == 48 and all(labelled[r["id"]]["line"] == r["line"] for r in shipped)


def test_a_suite_is_built_reproducibly_and_its_manifest_checks_every_scene(tiny_suite, tiny_def, tmp_path):
    m = tiny_suite.manifest
    assert (m.name, m.version, m.seed, m.engine, m.tasks) == ("tiny", 1, 0, "knowledge", 3)
    assert m.package_version and m.git_commit and m.settings["brainstorm"]["n"] == 3
    assert len(m.scenes) == 3 and not m.not_built and tiny_suite.task_ids == [s.task_id for s in m.scenes]
    assert verify_suite(tiny_suite) == []
    again = build_suite(tiny_def, tmp_path / "again", quiet=True)
    assert [(s.task_id, s.sha256, s.files) for s in again.scenes] == [(s.task_id, s.sha256, s.files) for s in m.scenes]
    copy = open_suite(tmp_path / "again")
    graph = copy.root / "scenes" / copy.task_ids[0] / "scene_graph.json"
    graph.write_text(graph.read_text().replace('"room"', ' "room"', 1))
    assert verify_suite(copy) == [f"{copy.task_ids[0]}: changed ({m.scenes[0].files} files, {m.scenes[0].files} when built)"]


def test_a_suite_name_not_built_says_how_to_build_it(tmp_path, monkeypatch):
    monkeypatch.setenv("ANOMALYGEN_SUITES", str(tmp_path))
    assert suite_dir("outside", 1) == tmp_path / "outside-v1"
    with pytest.raises(UserError, match="anomalygen suite build outside"):
        open_suite("outside")
    with pytest.raises(UserError, match="neither a folder nor a suite"):
        open_suite("no-such-suite")


def test_any_built_run_folder_is_a_suite(tiny_suite, tmp_path):
    import shutil

    run = tmp_path / "run"
    shutil.copytree(tiny_suite.root, run)
    (run / "suite.json").unlink()
    plain = open_suite(run)
    assert plain.manifest is None and plain.task_ids == tiny_suite.task_ids and plain.label == str(run)
