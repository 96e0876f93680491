"""Resume against the settings in the plan stage: a changed ``[plan]`` key re-plans, a key the planner
does not read (``[learn]`` above all, which it once fingerprinted) does not; and so from the CLI."""

from __future__ import annotations

import json

import pytest
from test_planner import _scene_with_a_drawer_and_two_sharp_things, _task

from support.resume import LLM, assert_resume, cases, settings, stage_reads

BASES = {"knowledge": {}, "llm": {"plan": {"engine": "llm"}, "llm": LLM}}


@pytest.mark.parametrize(("base", "key", "redo"), cases("plan", BASES))
def test_plans_are_redone_exactly_when_a_setting_they_read_changes(request, base, key, redo):
    assert_resume("plan", request, base, key, redo=redo)


def test_the_plan_stage_reads_plan_not_learn():
    for over in BASES.values():
        read = stage_reads("plan", settings(**over))
        assert {"plan.engine", "plan.source", "plan.max_fixes", "plan.min_score", "plan.sac_actions"} <= set(read)
        assert not [k for k in read if k.startswith(("learn.", "build.", "detect."))]
    assert "seed" not in stage_reads("plan", settings())  # the knowledge planner draws nothing at random
    assert {"seed", "llm.model"} <= set(stage_reads("plan", settings(**BASES["llm"])))


def test_max_fixes_from_the_environment_replans_a_run_planned_with_the_default(tmp_path, monkeypatch, capsys):
    """``ANOMALYGEN_PLAN__MAX_FIXES=1 anomalygen plan --run R`` on plans made with max_fixes = 3: the
    plan is made again, with one fix; a changed ``[learn]`` key then re-plans nothing."""
    from anomalygen.cli import main
    from anomalygen.runfolder import RunFolder, read_model, write_jsonl
    from anomalygen.schema import Detection, Hypothesis, Plan

    run = RunFolder.create(tmp_path / "r")
    write_jsonl(run.tasks_path, [_task("a", "store_sharp_objects")])
    _scene_with_a_drawer_and_two_sharp_things(run, "a")
    hyps = [Hypothesis(rank=1, problem="p", solution="s", target_object="scissors_0",
                       hazard_class="store_sharp_objects", score=0.75),
            Hypothesis(rank=2, problem="p", solution="s", target_object="knife_0",
                       hazard_class="keep_sharp_away_from_children", score=0.95)]
    write_jsonl(run.detections_path, [Detection(task_id="a", scene_id="s", detector="rules", hypotheses=hyps)])

    def plan() -> tuple[dict, list[str]]:
        main(["plan", "--run", str(run.root), "--quiet", "--json"])
        summary = json.loads(capsys.readouterr().out)
        made = read_model(run.plan_path("a"), Plan)
        return summary, [s.params["object"] for s in made.subtasks if s.primitive == "grasp"]

    summary, picks = plan()
    assert (summary["done"], picks) == (1, ["knife_0", "scissors_0"])  # the default: up to 3 fixes
    assert plan()[0]["skipped"] == 1
    monkeypatch.setenv("ANOMALYGEN_PLAN__MAX_FIXES", "1")
    summary, picks = plan()
    assert (summary["done"], summary["skipped"], picks) == (1, 0, ["knife_0"])
    monkeypatch.setenv("ANOMALYGEN_LEARN__SAC_STEPS", "5")  # the planner reads no [learn] key
    assert plan()[0]["skipped"] == 1
