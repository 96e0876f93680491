"""move_away on a scene the builder made, with the real simulator: the object ends the asked
distance from the other one, on a safe top."""

from __future__ import annotations

from pathlib import Path

import numpy as np
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


@pytest.mark.slow
def test_a_laptop_is_not_set_down_on_a_basket_for_want_of_a_clear_spot(tmp_path):
    """The seed-0 primitives run's t0062 at 99ecc74, built verbatim: a laptop on the floor by a sink;
    the one table holds a 0.45 m basket in its middle, leaving no clear spot a 0.45 m laptop fits.
    The spot rated best lay over the basket, so the laptop ended on it, at its edge: a new hazard
    (move_fragile_from_edge) while the skill's own check passed. A spot on something else is no spot."""
    from anomalygen.skills.scripted import relocate
    from support.built_task import episode_on_built_task

    fixture = Path(__file__).parent / "fixtures" / "laptop_by_sink_basket_table.json"
    ep = episode_on_built_task(fixture, tmp_path / "scene", primitives=True)
    before = ep.driver.aabb("laptop_0")
    res = relocate.move_away(ep, "laptop_0", "sink_0", 0.6)
    assert not res.success and "clear of what stands on it" in res.detail, res.detail
    after = ep.driver.aabb("laptop_0")
    assert np.allclose(before[0], after[0], atol=0.01)  # left where it was, not stacked on the basket
    assert ("laptop_0", "basket_0") not in {(r.subject, r.object) for r in ep.graph().relations}
