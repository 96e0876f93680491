"""A scene whose hazard endangers a small child offers a container that latches beside the one the
task names: only a latching container shuts the object away from a toddler, and the knowledge
engine's tasks often name a plain storage box."""

from __future__ import annotations

import pytest

from anomalygen.config import Settings
from anomalygen.runfolder import read_model
from anomalygen.schema import SceneSpec

from .conftest import make_task

QUIET = Settings(build={"clutter": 0, "near_misses": 0, "multi_hazard": 0.0, "hazard_free": 0.0})


def _build(task, tmp_path) -> SceneSpec:
    from anomalygen.scene.build import build_scene

    build_scene(task, seed=0, settings=QUIET, out_dir=tmp_path / task.id)
    return read_model(tmp_path / task.id / "scene.json", SceneSpec)


def _latching(spec: SceneSpec) -> list:
    from anomalygen.knowledge import load_kb
    from anomalygen.schema import LATCHING_PROPERTY

    kb = load_kb()
    return [o for o in spec.objects if LATCHING_PROPERTY in kb.properties_of(o.asset.category)]


def test_a_lighter_for_the_storage_box_gets_a_safe_beside_the_box(tmp_path):
    task = make_task("t-lighter-box", "keep_fire_starters_from_children", "Lighter", "Lighter", "table",
                     container="storage_box", room="bedroom")
    spec = _build(task, tmp_path)
    box = next(o for o in spec.objects if o.name == spec.bindings["$container"])
    assert box.asset.category == "storage_box"  # the task's own container stands
    (safe,) = _latching(spec)
    lighter = next(o for o in spec.objects if o.name == spec.bindings["$hazard"])
    assert safe.fixed and safe.support == "floor" and safe.cavities
    assert lighter.size <= 2 * max(safe.cavities[0].half_extents)


@pytest.mark.parametrize("cls", ["store_sharp_objects"])
def test_a_class_with_no_child_at_risk_gets_no_extra_container(tmp_path, cls):
    task = make_task("t-knife-box", cls, "Table", "kitchen_knife", "table", container="storage_box")
    assert _latching(_build(task, tmp_path)) == []


def test_the_offered_container_is_a_kind_the_class_stores_the_object_in(tmp_path):
    """A knife goes in a safe (drawn until it fits), never a medicine cabinet: the planner only looks
    for the kinds ``containers_for`` names, so a cabinet it would never use is no fix on offer."""
    from anomalygen.knowledge import load_kb

    kb = load_kb()
    task = make_task("t-knife-toddler", "keep_sharp_away_from_children", "Table", "Knife", "low_table",
                     container="storage_box")
    spec = _build(task, tmp_path)
    knife = next(o for o in spec.objects if o.name == spec.bindings["$hazard"])
    (extra,) = _latching(spec)
    assert extra.asset.category in kb.containers_for(kb.hazard_classes[task.hazard_class], "Knife")
    assert knife.size <= 2 * max(extra.cavities[0].half_extents)
