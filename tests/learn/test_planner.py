"""KB-recipe plans: every class with a recipe yields typed sub-tasks bound to scene instances."""

from anomalygen.knowledge.base import load_kb
from anomalygen.learn.planner import plan_from_kb
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
