"""Resume notices change: a changed detection re-plans, a changed plan re-runs its skill, a changed
setting the skill reads re-runs it (and no other setting does); a mistyped ``--only`` id is an error
in every per-item stage."""

from __future__ import annotations

import shutil

import pytest
from test_learn_stage import _task, scene  # noqa: F401  (the module-scoped built scene)

from anomalygen.config import Settings
from anomalygen.errors import UserError
from anomalygen.runfolder import RunFolder, read_jsonl, read_model, write_jsonl, write_model
from anomalygen.schema import Detection, Plan, PredicateCall, SkillResult, SuccessSpec
from support.resume import assert_resume, stage_reads
from support.resume import cases as resume_cases
from support.resume import settings as resume_settings


def _settings() -> Settings:
    s = Settings(quiet=True, workers=1)
    s.learn.video = False
    return s


def _run(tmp_path, scene_dir) -> RunFolder:
    run = RunFolder.create(tmp_path / "r")
    write_jsonl(run.tasks_path, [_task("a")])
    shutil.copytree(scene_dir, run.scene_dir("a"))
    return run


def test_a_changed_detection_is_planned_again(tmp_path, scene):  # noqa: F811 (the imported fixture)
    from anomalygen.detect.stage import run_stage as detect
    from anomalygen.plan.stage import run_stage as plan

    run = _run(tmp_path, scene[0])
    settings = _settings()
    assert detect(run, settings).done == 1 and plan(run, settings).done == 1
    assert plan(run, settings).skipped == 1
    first = read_model(run.plan_path("a"), Plan)
    assert first.subtasks  # the litter was detected and a fix planned
    dets = read_jsonl(run.detections_path, Detection)
    write_jsonl(run.detections_path, [d.model_copy(update={"hypotheses": []}) for d in dets])  # detected nothing
    again = plan(run, settings)
    assert (again.done, again.skipped) == (1, 0)
    assert read_model(run.plan_path("a"), Plan).subtasks == []  # nothing detected: leave the scene alone


def test_a_changed_plan_reruns_its_skill_and_only_that(tmp_path, scene):  # noqa: F811
    from anomalygen.learn.stage import run_stage as learn

    scene_dir, spec = scene
    run = _run(tmp_path, scene_dir)
    on_floor = PredicateCall(name="on_floor", args={"object": "$hazard"})
    plan = Plan(task_id="a", source="ground_truth", engine="knowledge", subtasks=[],
                success=SuccessSpec(predicates=[on_floor]), bindings=dict(spec.bindings))
    write_model(run.plan_path("a"), plan)
    settings = _settings()
    settings.learn.seeds = 2
    assert learn(run, settings).done == 2
    assert read_model(run.skill_dir("a", 0) / "result.json", SkillResult).success
    assert learn(run, settings).skipped == 2
    # the plan changes (its own check now says the litter must be off the floor): both seeds run again
    negated = on_floor.model_copy(update={"negate": True})
    write_model(run.plan_path("a"), plan.model_copy(update={"success": SuccessSpec(predicates=[negated])}))
    again = learn(run, settings)
    assert (again.done, again.skipped) == (2, 0)
    assert not read_model(run.skill_dir("a", 0) / "result.json", SkillResult).success
    # one more seed runs only the new seed; a rebuilt scene runs both again
    settings.learn.seeds = 3
    assert (learn(run, settings).done, learn(run, settings).skipped) == (1, 3)
    (run.scene_dir("a") / "scene_graph.json").write_text(
        (run.scene_dir("a") / "scene_graph.json").read_text().replace('"room"', '"room" ', 1))
    assert learn(run, settings).done == 3


@pytest.mark.parametrize("stage", ["build", "detect", "plan", "learn"])
def test_an_unknown_only_id_is_an_error_in_every_stage(tmp_path, stage):
    from anomalygen.stages import stage as registered

    run = RunFolder.create(tmp_path / "r")
    write_jsonl(run.tasks_path, [_task("t0001-knife"), _task("t0002-pills")])
    with pytest.raises(UserError, match=r"unknown task id in --only: 't0002-pill' \(closest: 't0002-pills'\); "
                                        r"the run has 2 task ids"):
        registered(stage).run(run, _settings(), only=["t0002-pill"])


LEARN_BASES = {"recheck": {}, "no_recheck": {"learn": {"recheck": False}}}


@pytest.mark.parametrize(("base", "key", "redo"), resume_cases("learn", LEARN_BASES))
def test_runs_are_redone_exactly_when_a_setting_they_read_changes(request, base, key, redo):
    """With a cheap double of the item: ``[learn]`` less ``seeds`` and, with the look-again on,
    ``plan.max_fixes`` redo every run; any other key (the master seed, ``[plan]``'s other keys) none."""
    assert_resume("learn", request, base, key, redo=redo)


def test_the_learn_stage_reads_max_fixes_only_for_its_look_again():
    read = stage_reads("learn", resume_settings())
    assert {"learn.sac_steps", "learn.recheck", "plan.max_fixes"} <= set(read)
    assert "learn.seeds" not in read and "seed" not in read
    assert [k for k in read if not k.startswith("learn.")] == ["plan.max_fixes"]
    assert "plan.max_fixes" not in stage_reads("learn", resume_settings(**LEARN_BASES["no_recheck"]))
