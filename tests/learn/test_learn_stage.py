"""Learn stage: task x seed items, result.json per item, resume, one bad item fails alone, class table."""

from __future__ import annotations

import shutil

import pytest

from anomalygen.schema import Plan, PredicateCall, SkillResult, SuccessSpec


def _task(tid, hazard_class="pick_up_floor_litter"):
    from anomalygen.schema import TaskProposal

    return TaskProposal(id=tid, name="n", explanation="e", description="d", category="household_hazard",
                        hazard_class=hazard_class, target_asset="Bucket",
                        scenario=dict(hazard_object="wrapper", room="office", placement="walkway", container="Bucket"),
                        provenance=dict(engine="knowledge", mode="brainstorm"))


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    from anomalygen.config import Settings
    from anomalygen.scene.build import build_scene

    out = tmp_path_factory.mktemp("stage_scene") / "s"
    spec = build_scene(_task("a"), seed=0, settings=Settings(build={"clutter": 1}), out_dir=out)
    return out, spec


def test_stage_writes_results_resumes_and_isolates_a_bad_item(tmp_path, scene):
    """Plans with no sub-tasks (just the check) keep this fast; the physics is tested in test_execute."""
    from anomalygen.config import Settings
    from anomalygen.learn.stage import run_stage
    from anomalygen.runfolder import RunFolder, read_model, write_jsonl, write_model

    scene_dir, spec = scene
    run = RunFolder.create(tmp_path / "r")
    write_jsonl(run.tasks_path, [_task("a"), _task("b", "close_open_furniture"), _task("c")])
    for tid in ("a", "b"):
        shutil.copytree(scene_dir, run.scene_dir(tid))
    (run.scene_dir("b") / "scene.xml").write_text("<mujoco><broken")  # b: a scene that cannot load
    on_floor = PredicateCall(name="on_floor", args={"object": "$hazard"})
    for tid in ("a", "b", "c"):  # c has a plan but no scene: not an item at all
        write_model(run.plan_path(tid), Plan(task_id=tid, source="ground_truth", engine="knowledge", subtasks=[],
                                             success=SuccessSpec(predicates=[on_floor]), bindings=dict(spec.bindings)))
    settings = Settings(quiet=True, workers=1)
    settings.learn.seeds = 2
    settings.learn.video = False
    s = run_stage(run, settings)
    assert s.done == 2 and s.failed == 2 and set(s.errors) == {"b@seed0", "b@seed1"}
    for seed in (0, 1):
        res = read_model(run.skill_dir("a", seed) / "result.json", SkillResult)
        assert res.seed == seed and res.success  # the wrapper is still on the floor: on_floor holds
        assert res.final_predicates[0].holds and res.video is None
    assert not (run.skill_dir("a", 0) / "video.mp4").exists()
    table = s.results["by_class"]
    # the robot's own check (on_floor) holds, but the hidden truth says the litter is still there
    assert table["pick_up_floor_litter"] == {"n": 2, "success": 2, "judged": 2, "resolved": 0, "new_hazards": 0,
                                             "on_safe": 0, "rate": 1.0, "resolved_rate": 0.0}
    outcome = read_model(run.skill_dir("a", 0) / "result.json", SkillResult).outcome
    assert outcome is not None and not outcome.resolved
    assert outcome.hazards[0].object == spec.bindings["$hazard"] and "still holds" in outcome.hazards[0].detail
    assert table["close_open_furniture"]["success"] == 0
    again = run_stage(run, settings)
    assert again.skipped == 2 and again.done == 0 and again.failed == 2


def test_the_robot_side_runs_without_any_truth_file_and_only_the_referee_needs_one(tmp_path, scene):
    """Detect, plan and learn on a run folder whose truth.json files are gone: the robot's work and
    its own verdict are unchanged; only the hidden-truth verdict is missing."""
    from anomalygen.config import Settings
    from anomalygen.detect.stage import run_stage as detect
    from anomalygen.learn.stage import run_stage as learn
    from anomalygen.plan.stage import run_stage as plan
    from anomalygen.runfolder import RunFolder, read_model, write_jsonl

    scene_dir, spec = scene
    runs = {}
    for name, keep_truth in (("with", True), ("without", False)):
        run = RunFolder.create(tmp_path / name)
        write_jsonl(run.tasks_path, [_task("a")])
        shutil.copytree(scene_dir, run.scene_dir("a"))
        if not keep_truth:
            (run.scene_dir("a") / "truth.json").unlink()
        settings = Settings(quiet=True, workers=1)
        settings.learn.video = False
        assert detect(run, settings).done == 1 and plan(run, settings).done == 1 and learn(run, settings).done == 1
        runs[name] = run
    with_truth = read_model(runs["with"].skill_dir("a", 0) / "result.json", SkillResult)
    without = read_model(runs["without"].skill_dir("a", 0) / "result.json", SkillResult)
    assert (runs["with"].plan_path("a").read_text() == runs["without"].plan_path("a").read_text())
    assert with_truth.success == without.success and without.outcome is None
    assert with_truth.outcome is not None and with_truth.outcome.resolved == with_truth.success


def test_no_robot_side_module_mentions_the_answer_key():
    """A static guard: detect's detectors, plan, learn and control code never name truth.json or the referee."""
    from pathlib import Path

    import anomalygen

    root = Path(anomalygen.__file__).parent
    robot_side = [p for pkg in ("plan", "control", "rl") for p in (root / pkg).rglob("*.py")]
    robot_side += [p for p in (root / "learn").rglob("*.py") if p.name != "stage.py"]  # learn/stage.py calls the referee
    robot_side += [root / "perception.py", root / "scene" / "env.py"]
    robot_side += [root / "detect" / n for n in ("rules.py", "llm_detector.py", "hybrid.py", "observation.py", "kbcheck.py",
                                                 "noise.py")]
    for p in robot_side:
        text = p.read_text()
        for key in ("truth.json", "TRUTH_FILE", "load_manifest", "evaluate.referee", "scene.truth", "HazardManifest"):
            assert key not in text, (p, key)
