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
    assert table["pick_up_floor_litter"] == {"n": 2, "success": 2, "rate": 1.0}
    assert table["close_open_furniture"]["success"] == 0
    again = run_stage(run, settings)
    assert again.skipped == 2 and again.done == 0 and again.failed == 2
