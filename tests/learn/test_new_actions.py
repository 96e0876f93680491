"""The recipe actions push_to, close_lid, open_lid, take_out_of and place_on, each executed on a scene
the scene stage built from a task of the class that uses it; the assertions read the physical end
state (the settled scene graph), not the robot's own verdict."""

from __future__ import annotations

import pytest

from anomalygen.knowledge.predicates import WALKWAY_CLEARANCE, aabb_gap
from anomalygen.schema import PredicateCall, SceneGraph, TaskProposal
from support.kb_scenes import build_with_kb_plans


def make_task(task_id, hazard_class, target, hazard, placement, *, room):
    return TaskProposal(
        id=task_id, name=f"task {task_id}", explanation="test", description=f"A {hazard} at {placement}.",
        category="household_hazard", hazard_class=hazard_class, target_asset=target,
        scenario=dict(hazard_object=hazard, room=room, placement=placement, container=None, co_objects=[]),
        provenance=dict(engine="knowledge", mode="brainstorm"))


TASKS = {
    "push": make_task("t-push", "push_heavy_item_out_of_walkway", "Table", "dumbbell", "walkway", room="living_room"),
    "lid": make_task("t-lid", "close_open_portable_container", "Box", "Box", "floor", room="bedroom"),
    "micro": make_task("t-micro-c", "remove_item_from_appliance", "Microwave", "fork", "inside:Microwave", room="kitchen"),
    "desk": make_task("t-desk", "pick_item_off_floor_onto_desk", "Table", "Phone", "floor", room="office"),
}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    return build_with_kb_plans(TASKS, tmp_path_factory.mktemp("new_action_scenes"), clutter=1)


def _initial(scene_dir) -> SceneGraph:
    from anomalygen.world.graph import load_scene, scene_graph

    m, d, spec = load_scene(scene_dir)
    return scene_graph(m, d, spec)


def _run(built, key, tmp_path, plan=None):
    from anomalygen.learn.execute import execute_plan
    from anomalygen.runfolder import read_model

    scene_dir, spec, kb_plan = built[key]
    res = execute_plan(scene_dir, plan or kb_plan, seed=0, final_graph_path=tmp_path / "final.json")
    return spec, res, read_model(tmp_path / "final.json", SceneGraph)


def _rel(g: SceneGraph, subject: str, predicate: str) -> list[str | None]:
    return [r.object for r in g.relations if r.subject == subject and r.predicate == predicate]


def _fraction(g: SceneGraph, obj: str, labels) -> float:
    o = g.get(obj)
    return max(abs(j.value - j.closed_value) / max(abs(j.range[1] - j.range[0]), 1e-6) for j in o.joints if j.label in labels)


@pytest.mark.slow
def test_push_to_slides_the_dumbbell_beside_the_table(built, tmp_path):
    spec, res, final = _run(built, "push", tmp_path)
    obj, table = spec.bindings["$hazard"], spec.bindings["$support"]
    before = _initial(built["push"][0])
    assert aabb_gap(before.get(obj), before.get(table), horizontal=True) > WALKWAY_CLEARANCE
    assert res.success, [s.detail for s in res.subtasks]
    after = final.get(obj)
    assert after.on_floor and after.height_above_floor < 0.02  # moved along the floor, never left on top of anything
    assert aabb_gap(after, final.get(table), horizontal=True) <= WALKWAY_CLEARANCE
    moved = sum((a - b) ** 2 for a, b in zip(after.position[:2], before.get(obj).position[:2], strict=True)) ** 0.5
    assert moved > 0.2


@pytest.mark.slow
def test_close_lid_then_open_lid_on_a_box(built, tmp_path):
    from anomalygen.plan.planner import step_to_subtask

    scene_dir, spec, plan = built["lid"]
    box = spec.bindings["$target"]
    assert _fraction(_initial(scene_dir), box, ("lid", "flap")) > 0.3
    closed_spec, res, final = _run(built, "lid", tmp_path)
    assert res.success and _fraction(final, box, ("lid", "flap")) <= 0.05
    # the same scene again, lid shut and then opened: open_lid lifts it at least a third of its travel
    opened = PredicateCall(name="joint_open", args={"object": box, "label": "lid|flap", "min_fraction": 0.3})
    reopen = step_to_subtask(1, "open_lid", {"object": "$target"}, plan.bindings, spec, [opened])
    two = plan.model_copy(update={"subtasks": [*plan.subtasks, reopen],
                                  "success": plan.success.model_copy(update={"predicates": [opened]})})
    _, res2, final2 = _run(built, "lid", tmp_path, plan=two)
    assert res2.subtasks[0].success and res2.subtasks[1].success, [s.detail for s in res2.subtasks]
    assert _fraction(final2, box, ("lid", "flap")) >= 0.3


@pytest.mark.slow
def test_take_out_of_the_microwave_and_place_on_the_counter(built, tmp_path):
    scene_dir, spec, _ = built["micro"]
    fork, mw, counter = spec.bindings["$hazard"], spec.bindings["$target"], spec.bindings["$support"]
    before = _initial(scene_dir)
    assert any((o or "").split(":")[0] == mw for o in _rel(before, fork, "inside"))
    assert _fraction(before, mw, ("door",)) < 0.05  # shut: the plan has to open it
    _, res, final = _run(built, "micro", tmp_path)
    assert res.success, [s.detail for s in res.subtasks]
    assert not _rel(final, fork, "inside")  # no longer inside the appliance (nor anything else)
    assert counter in [(o or "").split(":")[0] for o in _rel(final, fork, "on")]
    assert _fraction(final, mw, ("door",)) <= 0.1  # and the door is shut again


@pytest.mark.slow
def test_pick_a_phone_off_the_floor_onto_the_desk(built, tmp_path):
    spec, res, final = _run(built, "desk", tmp_path)
    phone, table = spec.bindings["$hazard"], spec.bindings["$support"]
    assert res.success, [s.detail for s in res.subtasks]
    assert not final.get(phone).on_floor
    assert table in [(o or "").split(":")[0] for o in _rel(final, phone, "on")]
    top = final.get(table).position[2] + final.get(table).size[2] / 2
    assert abs(final.get(phone).height_above_floor - top) < 0.05
