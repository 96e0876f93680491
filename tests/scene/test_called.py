"""A word the catalogue lacks is built as a proxy shape of its kind and keeps the user's name in the
scene: the scene file, the scene graph the robot perceives and the detector's scene text (issue 38)."""

from __future__ import annotations

import json

import pytest

from anomalygen.brainstorm.free_text import tasks_from_lines
from anomalygen.config import Settings
from anomalygen.knowledge import load_kb


@pytest.mark.slow
def test_the_oven_cleaner_is_built_and_perceived_as_oven_cleaner(tmp_path):
    from anomalygen.detect.observation import observation_text
    from anomalygen.scene.build import build_scene
    from anomalygen.schema import SceneGraph

    tasks, errors = tasks_from_lines(["Somebody left the oven cleaner on the low coffee table."], load_kb())
    assert not errors
    task = tasks[0]
    proxy = task.scenario.hazard_object
    build_scene(task, seed=0, settings=Settings(), out_dir=tmp_path)
    spec = json.loads((tmp_path / "scene.json").read_text())
    called = {o["name"]: o.get("called") for o in spec["objects"]}
    named = [n for n, c in called.items() if c == "oven cleaner"]
    assert len(named) == 1 and named[0].startswith(proxy.lower())  # the hazard instance, and only it
    graph = SceneGraph.model_validate_json((tmp_path / "scene_graph.json").read_text())
    assert graph.get(named[0]).called == "oven cleaner"
    assert f"{named[0]} (oven cleaner: {graph.get(named[0]).category}" in observation_text(graph)


@pytest.mark.slow
def test_what_a_line_states_is_checked_in_the_settled_scene(tmp_path):
    """A user's line is built as stated or not at all: the relation it put the object in and the states
    it gave the others are validation checks of the build, and a scene that lost one would fail."""
    from anomalygen.scene.build import build_scene
    from anomalygen.scene.validate import stated_checks
    from anomalygen.schema import SceneGraph, SceneSpec

    [task], _ = tasks_from_lines(["A power strip is lying in the bathroom sink, which is full of water."], load_kb())
    build_scene(task, seed=0, settings=Settings(), out_dir=tmp_path)
    spec = SceneSpec.model_validate_json((tmp_path / "scene.json").read_text())
    graph = SceneGraph.model_validate_json((tmp_path / "scene_graph.json").read_text())
    stated = {c.name: c.passed for c in stated_checks(task, spec, graph)}
    assert stated == {"stated:inside Sink": True, "stated:Sink contains_water": True}
    lost = graph.model_copy(update={"relations": [r for r in graph.relations if r.predicate != "inside"]})
    dry = lost.model_copy(update={"objects": [o.model_copy(update={"states": [s for s in o.states if s != "contains_water"]})
                                             for o in lost.objects]})
    assert [c.passed for c in stated_checks(task, spec, dry)] == [False, False]
