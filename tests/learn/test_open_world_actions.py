"""The open-world hazards' fixes (issue 25), each executed by the learn stage on a scene the scene stage
built with the new objects: switching off a stove's knob, a space heater's dial and the push switches
of a power strip, a hair dryer and an iron, putting a candle out with its snuffer, taking a towel off
a lit hob, moving a candle away from the curtains, turning a pan's handle inward and closing a baby
gate. Plans are written by hand as the planner would (its switch-off sub-tasks come from the planner
itself); the assertions read the settled final scene graph, not the robot's own verdict."""

from __future__ import annotations

import numpy as np
import pytest

from anomalygen.schema import Plan, SceneGraph, SceneSpec, SkillMethod, SubTask, SuccessSpec
from support.kb_scenes import NO_MIX
from support.kb_scenes import state_task as _task

TASKS = {
    # a kitchen has a counter beside the stove: the towel needs somewhere safe to go
    "stove": _task("w-stove", "Stove", "towel", "on:Stove", {"Stove": ["lit"]}, co=["counter"]),
    "devices": _task("w-devices", "SpaceHeater", "SpaceHeater", "floor",
                     {"SpaceHeater": ["on"], "PowerStrip": ["on"], "hair_dryer": ["on"]}, room="bedroom",
                     co=["Curtains", "PowerStrip", "hair_dryer"]),
    "candle": _task("w-candle", "candle", "candle", "table", {"candle": ["lit"], "iron": ["on"]}, room="living_room",
                    co=["Curtains", "iron", "StorageFurniture"]),
    "pan": _task("w-pan", "Stove", "frying_pan", "on:Stove", {"frying_pan": ["handle_out"]}),
    "gate": _task("w-gate", "Stairs", "toy_car", "floor", arts=[("BabyGate", "gate", "open")], room="hallway",
                  co=["BabyGate"]),
}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    from anomalygen.config import Settings
    from anomalygen.scene.build import build_scene

    root = tmp_path_factory.mktemp("open_world_actions")
    out = {}
    for key, task in TASKS.items():
        spec = build_scene(task, seed=0, settings=Settings(build={"clutter": 0, **NO_MIX}), out_dir=root / key)
        out[key] = (root / key, spec)
    return out


def _graph(scene_dir) -> SceneGraph:
    from anomalygen.world.graph import load_scene, scene_graph

    m, d, spec = load_scene(scene_dir)
    return scene_graph(m, d, spec)


def _one(graph: SceneGraph, category: str):
    (obj,) = [o for o in graph.objects if o.category == category]
    return obj


def _on(graph: SceneGraph, name: str) -> list[str]:
    return [(r.object or "").split(":")[0] for r in graph.relations if r.subject == name and r.predicate == "on"]


def _step(i: int, action: str, **params) -> SubTask:
    return SubTask(id=f"s{i}_{action}", description=action, method=SkillMethod.PRIMITIVE, primitive=action,
                   params=params)


def _switch_off(spec: SceneSpec, obj: str, method=SkillMethod.PRIMITIVE) -> list[SubTask]:
    """The planner's own switch-off sub-tasks (one per control that is on)."""
    from anomalygen.plan.planner import switch_off_subtasks

    return switch_off_subtasks(0, {"object": obj, "label": "knob|switch"}, dict(spec.bindings), spec, [], method)


def _run(built, key, subtasks, tmp_path):
    from anomalygen.learn.execute import execute_plan
    from anomalygen.runfolder import read_model

    scene_dir, spec = built[key]
    plan = Plan(task_id=spec.task_id, source="ground_truth", engine="knowledge", subtasks=subtasks,
                success=SuccessSpec(), bindings=dict(spec.bindings))
    res = execute_plan(scene_dir, plan, seed=0, final_graph_path=tmp_path / "final.json")
    return res, read_model(tmp_path / "final.json", SceneGraph)


def _off(graph: SceneGraph, name: str) -> bool:
    o = graph.get(name)
    return "off" in o.states and not {"on", "lit"} & set(o.states) and all(j.is_closed() for j in o.joints)


@pytest.mark.slow
def test_heater_dial_power_strip_and_hair_dryer_switched_off(built, tmp_path):
    """The knowledge planner's path: SAC with the family's warm start for the heater's knob and the
    power strip's push switch (its primitive on a failure), the scripted primitive for the dryer."""
    scene_dir, spec = built["devices"]
    before = _graph(scene_dir)
    names = {c: _one(before, c).name for c in ("SpaceHeater", "PowerStrip", "hair_dryer")}
    assert all("on" in before.get(n).states for n in names.values())
    plan = (_switch_off(spec, names["SpaceHeater"], SkillMethod.SAC) + _switch_off(spec, names["PowerStrip"], SkillMethod.SAC)
            + _switch_off(spec, names["hair_dryer"]))
    res, final = _run(built, "devices", plan, tmp_path)
    assert all(s.success for s in res.subtasks), [s.detail for s in res.subtasks]
    for name in names.values():
        assert _off(final, name), (name, final.get(name).states, final.get(name).joints)
        moved = np.linalg.norm(np.subtract(final.get(name).position[:2], before.get(name).position[:2]))
        assert moved < 0.1, (name, moved)  # switched off where it stands, not dragged about


@pytest.mark.slow
def test_stove_knob_off_and_towel_taken_off_the_hob(built, tmp_path):
    scene_dir, spec = built["stove"]
    before = _graph(scene_dir)
    stove, towel = _one(before, "Stove").name, _one(before, "towel").name
    assert {"on", "lit"} <= set(before.get(stove).states) and _on(before, towel) == [stove]
    res, final = _run(built, "stove", [*_switch_off(spec, stove), _step(2, "take_off", object=towel)], tmp_path)
    assert all(s.success for s in res.subtasks), [s.detail for s in res.subtasks]
    assert _off(final, stove)
    (holder,) = _on(final, towel)
    assert holder != stove and final.get(holder).category in ("Table", "counter", "shelf", "StorageFurniture")
    assert not final.get(towel).on_floor


@pytest.mark.slow
def test_candle_put_out_moved_away_from_the_curtains_and_iron_off(built, tmp_path):
    from anomalygen.skills.geometry import box_gap

    scene_dir, spec = built["candle"]
    before = _graph(scene_dir)
    candle, curtains, iron = (_one(before, c).name for c in ("candle", "Curtains", "iron"))
    assert {"on", "lit"} <= set(before.get(candle).states) and "on" in before.get(iron).states

    def gap(g):
        boxes = [(np.subtract(o.position, np.divide(o.size, 2)), np.add(o.position, np.divide(o.size, 2)))
                 for o in (g.get(candle), g.get(curtains))]
        return box_gap(*boxes)

    distance = max(0.9, gap(before) + 0.3)  # the recipe's 0.9 m, and never a move it has already made
    plan = [*_switch_off(spec, candle), *_switch_off(spec, iron),
            _step(3, "move_away", object=candle, **{"from": curtains, "distance": distance})]
    res, final = _run(built, "candle", plan, tmp_path)
    assert all(s.success for s in res.subtasks), [s.detail for s in res.subtasks]
    assert _off(final, candle) and _off(final, iron)
    assert gap(final) >= distance - 0.01
    (holder,) = _on(final, candle)
    assert final.get(holder).category in ("Table", "StorageFurniture") and not final.get(candle).on_floor
    assert final.get(candle).size[2] > final.get(candle).size[0]  # standing, not knocked over


@pytest.mark.slow
def test_pan_turned_with_its_handle_inward(built, tmp_path):
    scene_dir, _ = built["pan"]
    before = _graph(scene_dir)
    pan, stove = _one(before, "frying_pan").name, _one(before, "Stove").name
    assert "handle_out" in before.get(pan).states
    res, final = _run(built, "pan", [_step(1, "rotate_inward", object=pan)], tmp_path)
    assert res.subtasks[0].success, res.subtasks[0].detail
    assert "handle_out" not in final.get(pan).states and _on(final, pan) == [stove]
    assert final.get(pan).height_above_floor > 0.8  # set back down on the hob, not dropped
    # and back from the hob's edge, where the top has room: else it would be a heavy thing at an edge
    assert final.get(pan).distance_to_edge > 0.12, final.get(pan).distance_to_edge


@pytest.mark.slow
def test_baby_gate_closed(built, tmp_path):
    scene_dir, _ = built["gate"]
    before = _graph(scene_dir)
    gate = _one(before, "BabyGate")
    (hinge,) = gate.joints
    assert hinge.label == "gate" and hinge.open_fraction > 0.4
    res, final = _run(built, "gate", [_step(1, "close_joint", object=gate.name, part="gate")], tmp_path)
    assert res.subtasks[0].success, res.subtasks[0].detail
    (after,) = final.get(gate.name).joints
    assert after.is_closed()
