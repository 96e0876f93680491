"""Looking again after the plan: only hazards the robot's own actions created are re-planned."""

from __future__ import annotations

from tests.knowledge.graphs import furniture, graph, joint, obj

from anomalygen.knowledge import load_kb
from anomalygen.learn.recheck import new_hazards, repair_plan


def _scene(door: float, knife_on_floor: bool):
    cab = furniture("cab_0", "StorageFurniture", joints=[joint("door", door), joint("drawer", 0.0)])
    knife = obj("knife_0", "Knife", at="floor" if knife_on_floor else "counter", xy=(1.0, 0.0))
    return graph(cab, knife)


def test_a_door_the_plan_left_open_is_new_and_the_knife_it_did_not_touch_is_not():
    kb = load_kb()
    before = _scene(door=0.0, knife_on_floor=True)   # the knife was already the hazard on the floor
    after = _scene(door=0.6, knife_on_floor=True)    # the robot opened the cabinet and left it open
    assert ("cab_0", "close_open_furniture") in new_hazards(before, after, kb)
    assert all(o != "knife_0" for o, _ in new_hazards(before, after, kb))
    assert new_hazards(before, before, kb) == []


def test_the_repair_plan_closes_what_was_left_open_under_its_own_step_ids():
    kb = load_kb()
    after = _scene(door=0.6, knife_on_floor=True)
    found = new_hazards(_scene(door=0.0, knife_on_floor=True), after, kb)
    plan, problems = repair_plan("t", found, after, None, kb, max_fixes=3)
    assert problems == [] and plan is not None
    assert plan.subtasks and all(st.id.startswith("recheck_") for st in plan.subtasks)
    assert {st.params.get("object") for st in plan.subtasks} == {"cab_0"}
    assert plan.subtasks[0].primitive == "push"  # close_joint is a push on the open part
