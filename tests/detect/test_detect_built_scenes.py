"""Detection on scenes the real scene builder made (MuJoCo settle, graph from the simulated state)."""

from __future__ import annotations

import json

import pytest
from detect_graphs import make_task
from test_detect_observation import assert_no_leak

from anomalygen.config import load_settings
from anomalygen.detect.observation import observation_json, observation_text
from anomalygen.detect.stage import detect_scene
from anomalygen.runfolder import read_model
from anomalygen.schema import AuxiliaryItem, SceneGraph

TASKS = [
    make_task(
        "t-shears", "store_sharp_objects", "household_hazard", "garden_shears", "Stapler",
        "Garden shears abandoned by the sink",
        "Someone brought the garden shears inside to trim herbs and left them open right at the lip of the "
        "worktop, blades pointing out at hip height.",
        "Close the shears away in the box.", placement="counter_edge",
    ),
    make_task(
        "t-toycar", "remove_choking_hazards", "child_safety", "toy_car", "Remote",
        "A tiny toy car in the crawling zone",
        "A matchbox-sized toy car has been dropped in the middle of the living room carpet where the baby "
        "practises crawling and puts everything in her mouth.",
        "Put the toy car away in the storage box.", room="living_room", placement="walkway",
    ),
]
TASKS[0].scenario.container = "Box"
TASKS[0].auxiliary_items = [AuxiliaryItem(name="garden_shears", purpose="the hazard itself"),
                            AuxiliaryItem(name="Box", purpose="where the robot puts the item away")]
TASKS[1].scenario.container = "storage_box"
TASKS[1].auxiliary_items = [AuxiliaryItem(name="toy_car", purpose="the hazard itself"),
                            AuxiliaryItem(name="storage_box", purpose="where the robot puts the item away")]


@pytest.mark.slow
@pytest.mark.parametrize("task", TASKS[1:], ids=lambda t: t.id)  # one build keeps the area's test budget
def test_rules_find_the_hazard_in_a_built_scene_without_seeing_the_task(tmp_path, task):
    """The shears task (counter edge) passes too; it is kept here for a manual run with TASKS."""
    from anomalygen.scene.build import build_scene

    settings = load_settings(None, {"quiet": True, "build.clutter": 3})
    spec = build_scene(task, seed=0, settings=settings, out_dir=tmp_path)
    graph = read_model(tmp_path / "scene_graph.json", SceneGraph)
    assert_no_leak(observation_text(graph), task)
    assert_no_leak(json.dumps(observation_json(graph)), task)
    # every built object is shown, clutter included
    assert {o["name"] for o in observation_json(graph)["objects"]} == {o.name for o in spec.objects}
    det = detect_scene(task.id, graph, settings)
    assert det.hypotheses[0].target_object == spec.bindings["$hazard"]
    # scored on the evaluate side: the first claim names the scene's truth hazard
    from anomalygen.evaluate.detection_scores import finds, load_manifest

    truth = load_manifest(tmp_path)
    intended = next(z for z in truth.hazards if z.object == spec.bindings["$hazard"])
    assert finds(det.hypotheses[:1], intended) and intended.hazard_class == task.hazard_class
