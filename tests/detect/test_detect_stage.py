"""The detect stage on a run folder of hand-built scenes: files, collation, summary, resume, CLI."""

from __future__ import annotations

import json

import detect_graphs as g
import pytest

from anomalygen.config import load_settings
from anomalygen.detect.stage import run_stage
from anomalygen.errors import UserError
from anomalygen.runfolder import RunFolder, read_jsonl, read_model, write_jsonl, write_model
from anomalygen.schema import Detection, SceneSpec


def make_run(tmp_path, scenes):
    """scenes: [(task, graph, bindings)] -> a run folder as brainstorm + build leave it."""
    run = RunFolder.create(tmp_path / "run")
    write_jsonl(run.tasks_path, [t for t, _, _ in scenes])
    for task, graph, bindings in scenes:
        if graph is None:
            continue
        d = run.scene_dir(task.id)
        write_model(d / "scene_graph.json", graph)
        write_model(d / "scene.json", SceneSpec(scene_id=graph.scene_id, task_id=task.id, room=graph.room, seed=0,
                                                objects=[], bindings=bindings))
    return run


def standard_run(tmp_path):
    return make_run(tmp_path, [
        (g.KNIFE_TASK, g.knife_on_counter_edge(), {"$hazard": "kitchen_knife_0", "$target": "counter_0"}),
        (g.PILL_TASK, g.pill_on_floor(), {"$hazard": "pill_bottle_0"}),
        (g.FRIDGE_TASK, g.open_fridge(), {"$target": "refrigerator_0"}),
    ])


def settings(**over):
    return load_settings(None, {"quiet": True, "workers": 1, **over})


def test_rules_stage_writes_detections_only(tmp_path):
    run = standard_run(tmp_path)
    summary = run_stage(run, settings())
    assert (summary.done, summary.failed) == (3, 0)
    dets = read_jsonl(run.detections_path, Detection)
    assert [d.task_id for d in dets] == ["t-knife", "t-pill", "t-fridge"]  # task order
    assert [(d.hypotheses[0].target_object, d.hypotheses[0].hazard_class) for d in dets] == [
        ("kitchen_knife_0", "store_sharp_objects"), ("pill_bottle_0", "secure_medications"),
        ("refrigerator_0", "close_open_refrigerator")]
    assert all(d.detector == "rules" and not d.judgements and d.hit_rank is None for d in dets)
    assert all((run.detections_dir / f"{d.task_id}.json").is_file() for d in dets)
    assert not (run.root / "detections_summary.json").exists()  # scoring is evaluate's job


def test_the_detect_stage_never_reads_the_task_or_the_truth(tmp_path):
    """The same scenes under other task words and a truth file that lies: byte-identical detections."""
    plain, other = standard_run(tmp_path / "a"), standard_run(tmp_path / "b")
    tasks = other.load_tasks()
    for t in tasks:
        t.name, t.description, t.hazard_class = "something else", "a different story", "ventilate_room"
    write_jsonl(other.tasks_path, tasks)
    for t in tasks:
        (other.scene_dir(t.id) / "truth.json").write_text("not even json")
    run_stage(plain, settings())
    run_stage(other, settings())
    for t in tasks:
        assert (plain.detections_dir / f"{t.id}.json").read_text() == (other.detections_dir / f"{t.id}.json").read_text()


def test_unbuilt_scenes_are_left_to_build_and_unknown_ids_are_errors(tmp_path):
    run = make_run(tmp_path, [
        (g.KNIFE_TASK, g.knife_on_counter_edge(), {"$hazard": "kitchen_knife_0"}),
        (g.PILL_TASK, None, {}),
        (g.FRIDGE_TASK, g.open_fridge(), {"$target": "refrigerator_0"}),
    ])
    summary = run_stage(run, settings())
    assert summary.done == 2 and summary.failed == 0  # the unbuilt scene is build's failure, not ours
    with pytest.raises(UserError, match="no built scene for: t-pill"):
        run_stage(run, settings(), only=["t-pill"])
    with pytest.raises(UserError, match=r"unknown task id in --only: 't-pil' \(closest: 't-pill'\); the run has 3"):
        run_stage(run, settings(), only=["t-pil"])


def test_resume_skips_done_scenes_and_force_redoes_them(tmp_path):
    run = standard_run(tmp_path)
    run_stage(run, settings())
    again = run_stage(run, settings())
    assert (again.done, again.skipped) == (0, 3)
    assert len(read_jsonl(run.detections_path, Detection)) == 3
    forced = run_stage(run, settings(), force=True, only=["t-pill"])
    assert (forced.done, forced.skipped) == (1, 0)


def test_a_rebuilt_scene_is_detected_again(tmp_path):
    """Resume notices change: a scene graph that changed (a rebuild) redoes that scene's detection only."""
    run = standard_run(tmp_path)
    run_stage(run, settings())
    write_model(run.scene_dir("t-pill") / "scene_graph.json", g.two_hazards())  # the scene was rebuilt
    again = run_stage(run, settings())
    assert (again.done, again.skipped) == (1, 2) and set(again.results) == {"t-pill"}
    det = read_model(run.detections_dir / "t-pill.json", Detection)
    assert {h.target_object for h in det.hypotheses} >= {"marble_0", "kitchen_knife_0"}
    # a changed detect setting redoes every scene
    assert run_stage(run, settings(**{"detect.k": 2})).done == 3


def test_llm_detector_without_llm_is_a_clear_user_error(tmp_path):
    with pytest.raises(UserError, match="needs an LLM"):
        run_stage(standard_run(tmp_path), settings(**{"detect.detector": "llm"}))


def test_cli_detect(tmp_path, capsys):
    from anomalygen.cli import main

    run = standard_run(tmp_path)
    main(["detect", "--run", str(run.root), "--detector", "rules", "--k", "2", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert out["done"] == 3 and out["failed"] == 0
    assert all(len(d.hypotheses) <= 2 for d in read_jsonl(run.detections_path, Detection))
