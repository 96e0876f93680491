"""truth.json: every built scene carries its answer key, bound to the instances the builder placed."""

from __future__ import annotations

from anomalygen.knowledge import load_kb
from anomalygen.runfolder import read_model
from anomalygen.schema import HazardManifest, SceneGraph, SceneSpec

from .conftest import TASKS


def test_every_built_scene_has_a_manifest_whose_first_hazard_is_the_one_the_builder_set_up(built_scenes):
    kb = load_kb()
    for key, folder in built_scenes.items():
        task = TASKS[key]
        spec = read_model(folder / "scene.json", SceneSpec)
        graph = read_model(folder / "scene_graph.json", SceneGraph)
        truth = read_model(folder / "truth.json", HazardManifest)
        first = truth.hazards[0]
        hc = kb.hazard_classes[task.hazard_class]
        assert truth.scene_id == spec.scene_id and first.hazard_class == task.hazard_class
        assert first.source == "intended" and all(h.source in ("intended", "incidental") for h in truth.hazards)
        assert all(n.kind in ("object", "borderline", "state") for n in truth.near_misses)
        assert first.object == spec.bindings[hc.hazard_variable] and first.variable == hc.hazard_variable
        assert first.category == graph.get(first.object).category
        assert all(c.args.get("object") == first.object for c in first.success), first.success
        assert {h.object for h in truth.hazards}.isdisjoint({n.object for n in truth.near_misses})
        assert "truth" not in spec.files  # the robot's file list does not point at the answer key


def test_the_fridge_scenes_fault_is_the_fridge_and_its_success_is_a_closed_door(built_scenes):
    truth = read_model(built_scenes["fridge"] / "truth.json", HazardManifest)
    (call,) = truth.hazards[0].success
    assert truth.hazards[0].object.startswith("refrigerator_") and call.name == "joint_closed"
