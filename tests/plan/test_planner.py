"""KB-recipe plans: every class with a recipe yields typed sub-tasks bound to scene instances."""

from anomalygen.knowledge.base import load_kb
from anomalygen.plan.planner import plan_from_kb
from anomalygen.schema import Plan, SkillMethod


def test_every_kb_class_plans():
    kb = load_kb()
    for cid in kb.hazard_classes:
        plan = plan_from_kb("t", cid, {"$hazard": "knife_0", "$container": "drawer_0", "$target": "fridge_0", "$support": "shelf_0"})
        assert isinstance(plan, Plan) and plan.subtasks
        assert plan.success.predicates == list(kb.hazard_classes[cid].success)
        for st in plan.subtasks:
            assert st.method == SkillMethod.PRIMITIVE and st.reward is not None
            assert not any(str(v).startswith("$") for v in st.params.values())


def test_store_plan_is_pick_then_place_inside():
    plan = plan_from_kb("t", "store_sharp_objects", {"$hazard": "knife_0", "$container": "drawer_0"})
    assert [s.primitive for s in plan.subtasks] == ["grasp", "move_to"]
    assert plan.subtasks[1].params["region"] == "drawer_0"
    kinds = [t.kind for t in plan.subtasks[1].reward.terms]
    assert "inside" in kinds
    # the final step carries the class's success predicate
    assert plan.subtasks[1].success.predicates[0].name == "inside"


def _task(tid, hazard_class):
    from anomalygen.schema import Engine, HazardCategory, Provenance, Scenario, TaskProposal

    return TaskProposal(id=tid, name="n", explanation="e", description="d", category=HazardCategory.HOUSEHOLD_HAZARD,
                        hazard_class=hazard_class, target_asset="knife",
                        scenario=Scenario(hazard_object="knife", room="kitchen", placement="counter_edge"),
                        provenance=Provenance(engine=Engine.KNOWLEDGE, mode="plain"))


def test_plan_stage_writes_plans_and_fails_one_item(tmp_path):
    from anomalygen.config import Settings
    from anomalygen.plan.stage import run_stage
    from anomalygen.runfolder import RunFolder, read_model, write_jsonl

    run = RunFolder.create(tmp_path / "r")
    write_jsonl(run.tasks_path, [_task("a", "store_sharp_objects"), _task("b", "no_such_class")])
    summary = run_stage(run, Settings(quiet=True))
    assert summary.done == 1 and summary.failed == 1 and "b" in summary.errors
    plan = read_model(run.plan_path("a"), Plan)
    assert plan.source == "ground_truth" and len(plan.subtasks) == 2
    again = run_stage(run, Settings(quiet=True))
    assert again.skipped == 1


def test_detected_source_plans_the_top_hypothesis(tmp_path):
    from anomalygen.config import Settings
    from anomalygen.plan.stage import run_stage
    from anomalygen.runfolder import RunFolder, read_model, write_jsonl
    from anomalygen.schema import Detection, Hypothesis

    run = RunFolder.create(tmp_path / "r")
    write_jsonl(run.tasks_path, [_task("a", "store_sharp_objects")])
    hyps = [Hypothesis(rank=2, problem="p", solution="s", target_object="cup_0", hazard_class="store_sharp_objects"),
            Hypothesis(rank=1, problem="p", solution="s", target_object="scissors_0", hazard_class="store_sharp_objects")]
    write_jsonl(run.detections_path, [Detection(task_id="a", scene_id="a", detector="rules", hypotheses=hyps)])
    settings = Settings(quiet=True)
    settings.learn.plan_source = "detected"
    assert run_stage(run, settings).done == 1
    plan = read_model(run.plan_path("a"), Plan)
    assert plan.source == "detected" and plan.bindings["$hazard"] == "scissors_0"
    assert plan.subtasks[0].params["object"] == "scissors_0"
