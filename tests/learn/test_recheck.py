"""Looking again after the plan: only hazards the robot's own actions created are re-planned."""

from __future__ import annotations

from tests.knowledge.graphs import furniture, graph, joint, obj

from anomalygen.knowledge import load_kb
from anomalygen.learn.recheck import hazards_seen, new_hazards, repair_plan


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


def test_a_hazard_still_firing_on_an_object_the_robot_moved_counts_as_new():
    """The knife was within reach at the start; the robot carried it 1 m and set it down, again within
    reach: that is its own doing and is planned again. Left where it was, it is not."""
    kb = load_kb()
    before = _scene(door=0.0, knife_on_floor=True)
    knife = obj("knife_0", "Knife", at="floor", xy=(2.0, 0.0))
    cab = furniture("cab_0", "StorageFurniture", joints=[joint("door", 0.0), joint("drawer", 0.0)])
    moved = graph(cab, knife)
    found = new_hazards(before, moved, kb)
    assert [o for o, _ in found] == ["knife_0"]
    assert found[0] in set(hazards_seen(before, kb))  # the same class as at the start, at a new place
    assert new_hazards(before, before, kb) == []
