"""move_away on a scene the builder made, with the real simulator: the object ends the asked
distance from the other one, on a safe top."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.mark.slow
def test_a_phone_is_moved_the_full_distance_from_the_bathtub_onto_the_one_table(tmp_path):
    """The seed-0 loop's t0054 at 182830c, built verbatim: a phone on the bathroom floor beside a full
    bathtub, one table 0.14 m from the tub. The spot was rated with the phone lying along the table
    (0.61 m from the tub) and checked either way round (0.56 m), so the table was turned down and the
    skill failed: "no safe support has a spot ... at least 0.60 m from bathtub_0"."""
    from anomalygen.skills.geometry import box_gap
    from anomalygen.skills.scripted import relocate
    from support.built_task import episode_on_built_task

    ep = episode_on_built_task(Path(__file__).parent / "fixtures" / "phone_by_bathtub.json", tmp_path / "scene")
    res = relocate.move_away(ep, "phone_0", "bathtub_0", 0.6)
    assert res.success, res.detail
    lo, hi = ep.driver.aabb("bathtub_0")
    assert box_gap(ep.driver.aabb("phone_0"), (lo, hi, 0.6)) >= 0.6
    assert not ep.graph().get("phone_0").on_floor
