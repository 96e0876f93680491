"""Shared fixtures: a few representative scenes built once per test session (building costs ~1 s each)."""

from __future__ import annotations

from pathlib import Path

import pytest

from anomalygen.config import Settings
from anomalygen.schema import TaskProposal
from support.fixtures import scripted_server  # noqa: F401 - the scripted LLM server for the LLM scene engine


def make_task(
    task_id,
    hazard_class,
    target,
    hazard,
    placement,
    *,
    container=None,
    articulations=(),
    room="kitchen",
    co=(),
):
    return TaskProposal(
        id=task_id,
        name=f"task {task_id}",
        explanation="test",
        description=f"A {hazard} is at {placement} in the {room}.",
        category="household_hazard",
        hazard_class=hazard_class,
        target_asset=target,
        scenario=dict(
            hazard_object=hazard, room=room, placement=placement, container=container, co_objects=list(co)
        ),
        articulations=[dict(object=o, part=p, initial_state=s) for o, p, s in articulations],
        provenance=dict(engine="knowledge", mode="brainstorm"),
    )


TASKS = {
    "floor": make_task("t-floor", "remove_choking_hazards", "Safe", "button_battery", "floor"),
    "fridge": make_task(
        "t-fridge",
        "close_open_refrigerator",
        "Refrigerator",
        "Refrigerator",
        "floor",
        articulations=[("Refrigerator", "door", "open")],
    ),
    "knife_edge": make_task("t-knife", "store_sharp_objects", "Table", "kitchen_knife", "counter_edge"),
    "drawer": make_task(
        "t-drawer", "secure_medications", "StorageFurniture", "pill_bottle", "inside:StorageFurniture"
    ),
}


@pytest.fixture(scope="session")
def scene_settings() -> Settings:
    return Settings(build={"clutter": 1})


@pytest.fixture(scope="session")
def built_scenes(tmp_path_factory, scene_settings) -> dict[str, Path]:
    from anomalygen.scene.build import build_scene

    root = tmp_path_factory.mktemp("scenes")
    out = {}
    for key, task in TASKS.items():
        build_scene(task, seed=0, settings=scene_settings, out_dir=root / key)
        out[key] = root / key
    return out
