"""Brainstorming draws only what can be built: a thing goes inside a holder only if it fits there."""

from __future__ import annotations

from anomalygen.brainstorm.drawable import fits_inside, placements_for, why_not_drawable
from anomalygen.knowledge import load_kb
from anomalygen.scene import asset_choice


def test_an_object_longer_than_every_interior_is_never_placed_inside():
    """A spoon (at least 0.15 m) never fits a toaster's slot (under 2 cm across), nor a 0.8 m power
    cable a sink's basin: every such task failed its build, "does not fit a 0.01 m space"."""
    kb = load_kb()
    assert not fits_inside(kb, "spoon", "Toaster") and not fits_inside(kb, "fork", "Toaster")
    assert fits_inside(kb, "fork", "Microwave")
    water = kb.hazard_classes["take_electrical_out_of_water"]
    assert "inside:Sink" not in placements_for(kb, water, "power_cable")
    assert "inside:Bathtub" in placements_for(kb, water, "power_cable")
    assert "inside:Sink" in placements_for(kb, water, "PowerStrip")
    # a class whose only object never fits its only holder is not drawn at all, and says why
    toaster = kb.hazard_classes["remove_item_from_toaster"]
    assert "room inside" in why_not_drawable(kb, toaster)
    # the rule is the builder's own cap on what goes inside
    for seed in range(3):
        from anomalygen.assets.core import generate

        biggest = generate("Toaster", seed, size=asset_choice.size_bounds(kb, "Toaster")[1])
        assert asset_choice.cavity_cap(biggest) < asset_choice.size_bounds(kb, "spoon")[0]
