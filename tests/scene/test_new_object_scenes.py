"""Built scenes with the open-world hazard objects (issue 25): each new category compiles, settles
and validates, the states the task asks for are built and shown, and the scene graph reports them
from the simulation (so a fix shows at once)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from anomalygen.config import Settings
from anomalygen.errors import ItemFailed
from anomalygen.runfolder import read_model
from anomalygen.schema import SceneSpec
from anomalygen.world.graph import load_scene, scene_graph
from anomalygen.world.states import GLOW_ALPHA, WATER_ALPHA, refresh_glows
from support.kb_scenes import state_task as _task

TASKS = {
    "stove": _task("n-stove", "Stove", "towel", "on:Stove", {"Stove": ["lit"]}, co=["PaperTowels"]),
    "sink": _task("n-sink", "Sink", "PowerStrip", "inside:Sink", {"Sink": ["contains_water"], "PowerStrip": ["on"]}),
    "bath": _task("n-bath", "Bathtub", "hair_dryer", "on:Bathtub", {"Bathtub": ["contains_water"], "hair_dryer": ["on"]},
                  room="bathroom"),
    "heater": _task("n-heater", "SpaceHeater", "SpaceHeater", "floor", {"SpaceHeater": ["on"]}, room="bedroom",
                    co=["Curtains", "Blanket"]),
    "stairs": _task("n-stairs", "Stairs", "toy_car", "on:Stairs", arts=[("BabyGate", "gate", "open")], room="hallway",
                    co=["BabyGate"]),
    "bookcase": _task("n-book", "Bookcase", "toy_block", "on:Bookcase", room="living_room"),
    "crib": _task("n-crib", "Crib", "ball", "inside:Crib", room="nursery"),
    "pan": _task("n-pan", "Stove", "frying_pan", "on:Stove", {"frying_pan": ["handle_out"]}),
    "iron": _task("n-iron", "iron", "iron", "floor", {"iron": ["on"]}, room="bedroom", co=["candle"]),
}


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    from anomalygen.scene.build import build_scene

    root = tmp_path_factory.mktemp("new_objects")
    for key, task in TASKS.items():
        build_scene(task, seed=0, settings=Settings(build={"clutter": 0}), out_dir=root / key)
    return root


def _load(scenes, key):
    model, data, spec = load_scene(scenes / key)
    return model, data, spec, scene_graph(model, data, spec)


def _one(graph, category):
    (obj,) = [o for o in graph.objects if o.category == category]
    return obj


def _rel(graph, subject, predicate):
    return [r.object for r in graph.relations if r.subject == subject and r.predicate == predicate]


def _rests_on(graph, subject, holder) -> bool:
    """On the holder by contact (an AABB-based 'inside' of a concave holder, a flight of stairs or a
    tub with a deck, hides that 'on' until the graph reads declared cavities)."""
    return holder in _rel(graph, subject, "on") + _rel(graph, subject, "inside")


def _alpha(model, name):
    return float(model.geom_rgba[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name), 3])


def test_every_scene_validates_and_settles(scenes):
    for key in TASKS:
        spec = read_model(scenes / key / "scene.json", SceneSpec)
        assert spec.validation.ok, (key, spec.validation.reason)
        model, data, _, graph = _load(scenes, key)
        before = {o.name: np.array(o.position) for o in graph.objects}
        mujoco.mj_step(model, data, nstep=250)  # half a second more barely moves anything
        after = scene_graph(model, data, spec)
        assert max(np.linalg.norm(np.array(o.position) - before[o.name]) for o in after.objects) < 0.01, key


def test_towel_on_the_stove_over_the_burner_that_is_lit(scenes):
    model, data, spec, graph = _load(scenes, "stove")
    stove, towel = _one(graph, "Stove"), _one(graph, "towel")
    assert {"on", "lit"} <= set(stove.states) and "off" not in stove.states
    assert _rel(graph, towel.name, "on") == [stove.name]
    on = [j for j in stove.joints if not j.is_closed()]
    assert len(on) == 1 and on[0].label == "knob" and on[0].open_fraction >= 0.7
    k = on[0].name.split("/")[1].removesuffix("_joint")
    # every knob has a glow over its burner (the procedural cooktop's and the real range's alike)
    knobs = [j.name.split("/")[1].removesuffix("_joint") for j in stove.joints if j.label == "knob"]
    assert len(knobs) == 4
    glows = {g: _alpha(model, f"{stove.name}/{g}_glow") for g in knobs}
    assert glows == {g: pytest.approx(GLOW_ALPHA if g == k else 0.0) for g in knobs}
    # the lit burner is the one nearest the towel
    centres = {g: data.geom(f"{stove.name}/{g}_glow").xpos[:2] for g in knobs}
    nearest = min(centres, key=lambda g: np.linalg.norm(centres[g] - towel.position[:2]))
    assert nearest == k
    # turned off in the simulation, the graph says so and the glow goes out
    data.joint(on[0].name).qpos[0] = 0.0
    mujoco.mj_forward(model, data)
    after = scene_graph(model, data, spec).get(stove.name)
    assert "off" in after.states and not {"on", "lit"} & set(after.states)
    refresh_glows(model, data, spec)
    assert _alpha(model, f"{stove.name}/{k}_glow") == 0.0


def test_power_strip_on_in_a_sink_full_of_water(scenes):
    model, _, spec, graph = _load(scenes, "sink")
    sink, strip = _one(graph, "Sink"), _one(graph, "PowerStrip")
    assert "contains_water" in sink.states and "off" in sink.states and "running" not in sink.states
    assert "on" in strip.states and _rel(graph, strip.name, "inside") == [sink.name]
    assert _alpha(model, f"{sink.name}/water") == pytest.approx(WATER_ALPHA)
    placed = next(o for o in spec.objects if o.name == sink.name)
    assert placed.states == ["contains_water"]


def test_hair_dryer_on_by_a_full_bathtub(scenes):
    _, _, _, graph = _load(scenes, "bath")
    tub, dryer = _one(graph, "Bathtub"), _one(graph, "hair_dryer")
    assert "contains_water" in tub.states and "on" in dryer.states
    assert _rests_on(graph, dryer.name, tub.name)
    assert 0.45 <= dryer.height_above_floor <= 0.65  # on the tub's deck


def test_heater_on_near_the_curtains(scenes):
    model, data, spec, graph = _load(scenes, "heater")
    heater, curtains = _one(graph, "SpaceHeater"), _one(graph, "Curtains")
    assert "on" in heater.states and "lit" not in heater.states and heater.on_floor
    # a loose heater is turned with its dial to the robot, the side it is switched off from
    (dial,) = heater.joints
    out = data.xaxis[model.joint(dial.name).id][:2]  # the dial turns about its front, the catalogue -y
    to_base = np.array(spec.robot_base[:2]) - np.array(heater.position[:2])
    assert np.dot(out, to_base) / np.linalg.norm(to_base) > 0.7
    assert curtains.size[2] >= 1.5 and curtains.states == []
    assert _one(graph, "Blanket").states == []


def test_toy_on_a_stair_beside_an_open_gate(scenes):
    _, _, _, graph = _load(scenes, "stairs")
    stairs, toy, gate = _one(graph, "Stairs"), _one(graph, "toy_car"), _one(graph, "BabyGate")
    assert _rests_on(graph, toy.name, stairs.name) and 0.15 < toy.height_above_floor < 0.8
    (hinge,) = gate.joints
    assert hinge.label == "gate" and hinge.open_fraction > 0.4 and not hinge.is_closed()


def test_book_on_the_high_shelf_and_ball_in_the_crib(scenes):
    _, _, _, graph = _load(scenes, "bookcase")
    book = _one(graph, "toy_block")
    assert book.height_above_floor >= 1.4 and not book.child_reachable
    _, _, _, graph = _load(scenes, "crib")
    assert _rel(graph, _one(graph, "ball").name, "inside") == [_one(graph, "Crib").name]


def test_pan_handle_out_until_it_is_turned_inward(scenes):
    model, data, spec, graph = _load(scenes, "pan")
    pan = _one(graph, "frying_pan")
    assert pan.states == ["handle_out"] and _rel(graph, pan.name, "on") == [_one(graph, "Stove").name]
    # turn the pan half a turn about its centre: the handle now lies over the stove
    jnt = model.joint(f"{pan.name}/free")
    adr = model.jnt_qposadr[jnt.id]
    centre = data.body(pan.name).xipos.copy()
    quat = np.zeros(4)
    mujoco.mju_mulQuat(quat, np.array([0.0, 0.0, 0.0, 1.0]), data.qpos[adr + 3:adr + 7].copy())
    data.qpos[adr + 3:adr + 7] = quat
    data.qpos[adr:adr + 2] += 2 * (centre[:2] - data.qpos[adr:adr + 2])
    mujoco.mj_forward(model, data)
    assert "handle_out" not in scene_graph(model, data, spec).get(pan.name).states


def test_iron_on_face_down_and_a_candle_out_by_default(scenes):
    model, data, spec, graph = _load(scenes, "iron")
    iron, candle = _one(graph, "iron"), _one(graph, "candle")
    assert {"on", "face_down"} <= set(iron.states)
    assert candle.states == ["off"] and _alpha(model, f"{candle.name}/snuffer_glow") == 0.0
    # raising the snuffer lights it: on and lit, the flame shows
    (snuffer,) = candle.joints
    data.joint(snuffer.name).qpos[0] = 0.8 * max(snuffer.range)
    mujoco.mj_forward(model, data)
    assert {"on", "lit"} <= set(scene_graph(model, data, spec).get(candle.name).states)
    refresh_glows(model, data, spec)
    assert _alpha(model, f"{candle.name}/snuffer_glow") == pytest.approx(GLOW_ALPHA)
    # stood on its heel it is no longer face down
    adr = model.jnt_qposadr[model.joint(f"{iron.name}/free").id]
    data.qpos[adr + 3:adr + 7] = [math.cos(math.pi / 4), 0.0, math.sin(math.pi / 4), 0.0]
    mujoco.mj_forward(model, data)
    assert "face_down" not in scene_graph(model, data, spec).get(iron.name).states


def test_a_state_the_scene_cannot_hold_is_refused(tmp_path):
    from anomalygen.scene.build import build_scene

    bad = _task("n-bad", "Table", "towel", "table", {"towel": ["contains_water"]})
    with pytest.raises(ItemFailed, match="towel cannot hold water; what can: Bathtub, Sink"):
        build_scene(bad, seed=0, settings=Settings(build={"clutter": 0, "repair_attempts": 0}), out_dir=tmp_path)
    odd = _task("n-odd", "Table", "towel", "table", {"towel": ["boiling"]})
    with pytest.raises(ItemFailed, match="no way to build the state 'boiling'"):
        build_scene(odd, seed=0, settings=Settings(build={"clutter": 0, "repair_attempts": 0}), out_dir=tmp_path)
