"""Learn stage: task x seed items, result.json and the final state per item, resume, one bad item fails
alone, the robot's own table; the referee's verdict comes after, from the judge stage."""

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
    # learn counts the robot's own check only (on_floor holds); it never reads a verdict
    assert table["pick_up_floor_litter"] == {"n": 2, "success": 2, "rate": 1.0}
    assert table["close_open_furniture"]["success"] == 0
    res = read_model(run.skill_dir("a", 0) / "result.json", SkillResult)
    assert res.outcome is None and (run.skill_dir("a", 0) / "final_state.npz").is_file()
    again = run_stage(run, settings)
    assert again.skipped == 2 and again.done == 0 and again.failed == 2
    # the referee, afterwards: the litter is still on the floor, whatever the robot believes
    from anomalygen.referee import load_verdict
    from anomalygen.referee.stage import run_stage as judge

    judged = judge(run, settings)
    verdict = load_verdict(run, "a", 0)
    assert verdict.status == "unresolved" and verdict.hazards[0].object == spec.bindings["$hazard"]
    assert "pick_up_floor_litter fires" in verdict.hazards[0].detail
    row = judged.results["by_class"]["pick_up_floor_litter"]
    assert (row["runs"], row["judged"], row["resolved"], row["robot_done"]) == (2, 2, 0, 2)


def test_the_robot_side_runs_without_any_truth_file_and_only_the_referee_needs_one(tmp_path, scene):
    """Detect, plan and learn on a run folder whose truth.json files are gone: the robot's work and
    its own verdict are unchanged; only the referee's verdict is missing."""
    from anomalygen.config import Settings
    from anomalygen.detect.stage import run_stage as detect
    from anomalygen.learn.stage import run_stage as learn
    from anomalygen.plan.stage import run_stage as plan
    from anomalygen.referee import load_verdict
    from anomalygen.referee.stage import run_stage as judge
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
        judge(run, settings)
        runs[name] = run
    with_truth = read_model(runs["with"].skill_dir("a", 0) / "result.json", SkillResult)
    without = read_model(runs["without"].skill_dir("a", 0) / "result.json", SkillResult)
    assert (runs["with"].plan_path("a").read_text() == runs["without"].plan_path("a").read_text())
    def robot_side(res: SkillResult):
        return (res.success, [(s.id, s.success, s.steps, s.detail) for s in res.subtasks], res.final_predicates)

    assert robot_side(with_truth) == robot_side(without)
    assert load_verdict(runs["without"], "a", 0) is None
    assert load_verdict(runs["with"], "a", 0) is not None
