"""The detect stage on a run folder of hand-built scenes: files, collation, resume, CLI; its detections
judged afterwards on the evaluate side (hit@k, detections_summary.json)."""

from __future__ import annotations

import json

import detect_graphs as g
import pytest

from anomalygen.config import load_settings
from anomalygen.detect.stage import run_stage
from anomalygen.errors import UserError
from anomalygen.evaluate.detection_report import DetectionReport, summary_path
from anomalygen.evaluate.judged_detections import judge_detections
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


def test_rules_stage_writes_detections_and_evaluate_judges_them(tmp_path):
    run = standard_run(tmp_path)
    summary = run_stage(run, settings())
    assert (summary.done, summary.failed) == (3, 0)
    dets = read_jsonl(run.detections_path, Detection)
    assert [d.task_id for d in dets] == ["t-knife", "t-pill", "t-fridge"]  # task order
    # the detect stage writes claims only: no judgement of them, no summary against the task
    assert all(not d.judged and d.hit_rank is None and d.judgements == [] for d in dets)
    assert not summary_path(run).exists()
    judge_detections(run, settings())
    dets = read_jsonl(run.detections_path, Detection)
    assert all(d.judged and d.hit_rank == 1 and d.detector == "rules" for d in dets)
    assert all((run.detections_dir / f"{d.task_id}.json").is_file() for d in dets)
    report = read_model(summary_path(run), DetectionReport)
    assert report.overall.rate == {1: 1.0, 2: 1.0, 3: 1.0}
    assert report.per_category["child_safety"].n == 1
    assert report.confusion["close_open_refrigerator"] == {"close_open_refrigerator": 1}
    assert report.misses == []
    assert report.judge_methods == {"exact": 3}


def test_misses_are_listed_with_reasons_and_unbuilt_scenes_reported(tmp_path):
    # the knife task is told its hazard is the mug: the detector's (correct) knife answer must count as a miss
    run = make_run(tmp_path, [
        (g.KNIFE_TASK, g.knife_on_counter_edge(), {"$hazard": "mug_0"}),
        (g.PILL_TASK, None, {}),
        (g.FRIDGE_TASK, g.open_fridge(), {"$target": "refrigerator_0"}),
    ])
    summary = run_stage(run, settings())
    assert summary.done == 2 and summary.failed == 0  # the unbuilt scene is build's failure, not ours
    with pytest.raises(UserError, match="no built scene for: t-pill"):
        run_stage(run, settings(), only=["t-pill"])
    judge_detections(run, settings())
    report = read_model(summary_path(run), DetectionReport)
    assert report.missing_scenes == ["t-pill"]
    assert report.overall.rate[1] == 0.5
    (miss,) = report.misses
    assert miss.task_id == "t-knife" and miss.top1 == "kitchen_knife_0/store_sharp_objects"
    assert "right class, wrong object" in miss.reason
    assert report.confusion["store_sharp_objects"] == {"store_sharp_objects": 1}


def test_resume_skips_done_scenes_and_force_redoes_them(tmp_path):
    run = standard_run(tmp_path)
    run_stage(run, settings())
    again = run_stage(run, settings())
    assert (again.done, again.skipped) == (0, 3)
    assert len(read_jsonl(run.detections_path, Detection)) == 3
    forced = run_stage(run, settings(), force=True, only=["t-pill"])
    assert (forced.done, forced.skipped) == (1, 0)
    # judging notices the re-detected scene: judged again, the others kept
    judge_detections(run, settings())
    run_stage(run, settings(), force=True, only=["t-pill"])
    assert [d.judged for d in read_jsonl(run.detections_path, Detection)] == [True, False, True]
    judge_detections(run, settings())
    assert all(d.judged for d in read_jsonl(run.detections_path, Detection))


def test_llm_detector_without_llm_is_a_clear_user_error(tmp_path):
    with pytest.raises(UserError, match="needs an LLM"):
        run_stage(standard_run(tmp_path), settings(**{"detect.detector": "llm"}))


def test_cli_detect(tmp_path, capsys):
    from anomalygen.cli import main

    run = standard_run(tmp_path)
    main(["detect", "--run", str(run.root), "--detector", "rules", "--k", "2", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert out["done"] == 3 and out["failed"] == 0
    judge_detections(run, settings(**{"detect.k": 2}))
    report = read_model(summary_path(run), DetectionReport)
    assert report.k == 2 and report.overall.rate[1] == 1.0
