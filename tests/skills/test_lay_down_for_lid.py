"""Putting a thing into a lidded box it would stand out of, on a scene the builder made, with the real
simulator: it is laid on its side first, and the lid shuts over it."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.mark.slow
def test_a_watering_can_taller_than_the_box_is_laid_down_and_the_lid_shuts_over_it(tmp_path):
    """The seed-0 loop's t0097 at 4726c82, built verbatim: a watering can 0.2 m tall, 0.16 m wide, to go
    into a storage box about 0.17 m deep. Stood upright, the lid shut on it and shoved it back out and
    the run stayed unresolved."""
    from anomalygen.skills.scripted import access, primitives
    from anomalygen.skills.scripted.laydown import tip_direction_for_lid
    from support.built_task import episode_on_built_task

    ep = episode_on_built_task(Path(__file__).parent / "fixtures" / "watering_can_storage_box.json",
                               tmp_path / "scene")
    assert access.open_for_access(ep, "storage_box_0", ["lid"]).success
    assert primitives.grasp(ep, "watering_can_0").success
    assert tip_direction_for_lid(ep, "watering_can_0", "storage_box_0") is not None
    placed = primitives.move_to(ep, "watering_can_0", "storage_box_0")
    assert placed.success and "laid on its side" in placed.detail, placed.detail
    assert access.close_opened(ep, "storage_box_0").success
    ep.settle(50)
    assert abs(float(ep.driver.data.joint("storage_box_0/lid_hinge").qpos[0])) < 0.05
    inside = {(r.subject, r.object) for r in ep.graph().relations if r.predicate == "inside"}
    assert ("watering_can_0", "storage_box_0") in inside


@pytest.mark.slow
def test_a_thing_that_fits_standing_is_not_laid_down(tmp_path):
    """The same box and scene: the tissue box, 0.11 m high, fits standing and goes in as it is."""
    from anomalygen.skills.scripted import access, primitives
    from anomalygen.skills.scripted.laydown import tip_direction_for_lid
    from support.built_task import episode_on_built_task

    ep = episode_on_built_task(Path(__file__).parent / "fixtures" / "watering_can_storage_box.json",
                               tmp_path / "scene")
    assert access.open_for_access(ep, "storage_box_0", ["lid"]).success
    assert primitives.grasp(ep, "tissue_box_0").success
    assert tip_direction_for_lid(ep, "tissue_box_0", "storage_box_0") is None
