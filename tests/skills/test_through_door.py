"""Putting a thing into a cabinet through one opened door, on a scene the builder made, with the real
simulator: it goes in the way it fits, and the door shuts on it."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.mark.slow
def test_a_towel_as_wide_as_one_door_goes_in_lengthwise_and_the_door_shuts(tmp_path):
    """The seed-0 loop's t0056 at 4726c82, built verbatim: a folded towel 0.40 x 0.29 m on the floor, to
    go into a low two-door cabinet through its left door (0.48 m wide, 0.76 m deep). Turned with its
    long side across the opening it caught the frame on both sides and stayed outside."""
    from anomalygen.skills.scripted import access, primitives
    from support.built_task import episode_on_built_task

    ep = episode_on_built_task(Path(__file__).parent / "fixtures" / "towel_cabinet_door.json", tmp_path / "scene")
    assert access.open_for_access(ep, "storagefurniture_0", ["door"]).success
    assert primitives.grasp(ep, "towel_0").success
    placed = primitives.move_to(ep, "towel_0", "storagefurniture_0")
    assert placed.success and "slid into" in placed.detail, placed.detail
    assert access.close_opened(ep, "storagefurniture_0").success
    ep.settle(50)
    graph = ep.graph()
    assert ("towel_0", "storagefurniture_0") in {(r.subject, r.object) for r in graph.relations
                                                 if r.predicate == "inside"}
    cabinet = graph.get("storagefurniture_0")
    assert all(abs(j.value - j.closed_value) < 0.05 for j in cabinet.joints if j.label == "door")
