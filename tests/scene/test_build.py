"""Scene building: the hazard is physically real in the settled scene, outputs are complete."""

import math
import subprocess
import sys

import mujoco
import numpy as np
import pytest

from anomalygen.knowledge import load_kb
from anomalygen.knowledge.predicates import evaluate
from anomalygen.runfolder import read_model
from anomalygen.schema import SceneGraph, SceneSpec
from anomalygen.world.graph import load_scene, scene_graph

from .conftest import TASKS


def _load(built_scenes, key):
    model, data, spec = load_scene(built_scenes[key])
    return model, data, spec, scene_graph(model, data, spec)


def _rel(graph, subject, predicate):
    return [r.object for r in graph.relations if r.subject == subject and r.predicate == predicate]


def test_outputs_written_and_valid(built_scenes):
    for key, folder in built_scenes.items():
        spec = read_model(folder / "scene.json", SceneSpec)
        assert spec.validation.ok, (key, spec.validation.reason)
        for name in (
            "scene.xml",
            "scene_graph.json",
            "render_front.png",
            "render_top.png",
            "render_wrist.png",
        ):
            assert (folder / name).stat().st_size > 100, name
        assert (folder / "assets" / "franka" / "collision" / "link0.stl").is_file()
        pen = next(c for c in spec.validation.checks if c.name == "max_penetration")
        assert pen.value <= 0.001


def test_robot_stands_at_its_base_pose(built_scenes):
    for key in built_scenes:
        model, data, spec, _ = _load(built_scenes, key)
        x, y, yaw = spec.robot_base
        ee = data.site("ee_site").xpos
        heading = np.array([np.cos(yaw), np.sin(yaw)])
        assert np.linalg.norm(data.body("base").xpos[:2] - [x, y]) < 0.01
        assert 0.2 < float((ee[:2] - [x, y]) @ heading) < 0.4  # the cup hangs in front of the base


def test_scene_xml_loads_from_any_cwd(built_scenes, tmp_path):
    xml = built_scenes["floor"] / "scene.xml"
    code = f"import mujoco; m = mujoco.MjModel.from_xml_path({str(xml)!r}); print(m.nbody)"
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, check=True
    )
    assert int(out.stdout.strip()) > 10


def test_object_on_floor_rests_on_floor(built_scenes):
    model, data, spec, graph = _load(built_scenes, "floor")
    hazard = graph.get(spec.bindings["$hazard"])
    assert hazard.on_floor and hazard.height_above_floor < 0.005
    assert hazard.child_reachable
    assert spec.bindings["$hazard"] in [r.subject for r in graph.relations if r.predicate == "on_floor"]
    # at rest: a further second of physics barely moves it
    before = np.array(hazard.position)
    mujoco.mj_step(model, data, nstep=500)
    after = np.array(scene_graph(model, data, spec).get(hazard.name).position)
    assert np.linalg.norm(after - before) < 0.005


def test_fridge_door_open_at_least_45_degrees(built_scenes):
    _, _, spec, graph = _load(built_scenes, "fridge")
    fridge = graph.get(spec.bindings["$target"])
    doors = [j for j in fridge.joints if j.label == "door"]
    assert doors
    assert max(abs(j.value - j.closed_value) for j in doors) >= math.radians(45)


def test_knife_on_counter_edge(built_scenes):
    _, _, spec, graph = _load(built_scenes, "knife_edge")
    knife = graph.get(spec.bindings["$hazard"])
    counter = spec.bindings["$support"]
    assert counter in _rel(graph, knife.name, "on")
    assert knife.distance_to_edge is not None and 0.0 <= knife.distance_to_edge <= 0.12
    assert knife.height_above_floor > 0.8
    assert not knife.on_floor


def test_item_inside_open_storage(built_scenes):
    _, _, spec, graph = _load(built_scenes, "drawer")
    pill = graph.get(spec.bindings["$hazard"])
    holder = next(o for o in spec.objects if o.name == pill.name).inside
    assert holder in _rel(graph, pill.name, "inside")
    openings = [j for j in graph.get(holder).joints if j.label in ("door", "drawer")]
    assert max(j.open_fraction for j in openings) > 0.3
    assert pill.child_reachable  # open furniture: a child can get at it


def test_rebuilt_graph_matches_saved_and_preconditions_hold(built_scenes):
    kb = load_kb()
    for key, folder in built_scenes.items():
        model, data, spec, graph = _load(built_scenes, key)
        saved = read_model(folder / "scene_graph.json", SceneGraph)
        assert [o.name for o in saved.objects] == [o.name for o in graph.objects]
        for a, b in zip(saved.objects, graph.objects, strict=True):
            assert np.allclose(a.position, b.position, atol=2e-3), (key, a.name)
        hc = kb.hazard_classes[TASKS[key].hazard_class]
        for call in hc.preconditions:
            assert evaluate(call, graph, spec.bindings).holds, (key, call)


def test_graph_carries_no_task_text(built_scenes):
    for key, folder in built_scenes.items():
        text = (folder / "scene_graph.json").read_text().lower()
        task = TASKS[key]
        for secret in (
            task.name.lower(),
            task.description.lower(),
            task.hazard_class.lower(),
            task.id.lower(),
        ):
            assert secret not in text, (key, secret)


def test_build_is_deterministic(built_scenes, scene_settings, tmp_path):
    from anomalygen.scene.build import build_scene

    spec = build_scene(TASKS["floor"], seed=0, settings=scene_settings, out_dir=tmp_path / "again")
    first = read_model(built_scenes["floor"] / "scene.json", SceneSpec)
    assert [o.name for o in spec.objects] == [o.name for o in first.objects]
    assert np.allclose([o.pos for o in spec.objects], [o.pos for o in first.objects], atol=1e-9)
    assert spec.robot_base == first.robot_base  # the start pose is drawn from the scene's generator


def test_unknown_placement_is_refused_with_one_line_reason():
    """A placement the builder has no relation kind for never reaches it: the task itself does not load
    (the schema's ``Placement`` knows every kind the builder builds)."""
    from pydantic import ValidationError

    from anomalygen.schema import format_validation_error

    from .conftest import make_task

    with pytest.raises(ValidationError) as err:
        make_task("t-bad", "remove_choking_hazards", "Safe", "button_battery", "ceiling")
    reason = format_validation_error(err.value)
    assert "\n" not in reason and "ceiling" in reason
