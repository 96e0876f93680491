"""Physics validation: every category over a couple of seeds, and that broken assets are caught."""

from __future__ import annotations

import numpy as np
import pytest

from anomalygen.assets import generate, household_names, target_names
from anomalygen.assets.finalize import finalize
from anomalygen.assets.model import Draft
from anomalygen.assets.parts import Part
from anomalygen.assets.validate import check_joints, check_rest, validate_asset
from anomalygen.rng import item_rng

pytestmark = pytest.mark.slow


@pytest.mark.parametrize("name", target_names())
def test_target_category_validates_over_seeds(name):
    for seed in (0, 7):
        result = validate_asset(generate(name, seed), render=False)
        assert result.ok, f"{name} seed {seed}: {result.reason}"
        names = {c.name for c in result.checks}
        assert {"compile", "rest"} <= names


def test_household_objects_rest_still():
    for name in household_names():
        a = generate(name, 1)
        check = check_rest(a)
        assert check.passed, f"{name}: {check.detail}"
        assert check.value is not None and check.value <= 0.01


def test_thumbnail_renders():
    result = validate_asset(generate("Microwave", 2), render=True)
    render = next(c for c in result.checks if c.name == "render")
    assert result.ok and render.passed and render.value > 2.0


def _rolling_ball():
    root = Part("root")
    root.sphere(0.08, (0, 0, 0.08), density=90)
    root.sphere(0.03, (0.05, 0, 0.08), density=8000)  # heavy lump inside, off-centre: it must roll
    return Draft(root)


def test_rest_check_catches_an_asset_that_rolls_away():
    a = finalize(_rolling_ball(), name="ball", seed=0, size=None, rng=item_rng(0, "x"))
    check = check_rest(a)
    assert not check.passed and check.value > 0.01


def _flap_into_floor():
    root = Part("root")
    root.box((0.15, 0.1, 0.05), (0, 0, 0.05))
    flap = root.child("flap", (0, -0.1, 0.0))
    flap.hinge("flap_hinge", (1, 0, 0), (0, 2.6), "door", 0.0)  # past horizontal: it hits the floor
    flap.box((0.14, 0.005, 0.15), (0, -0.005, 0.15))
    return Draft(root)


def test_joint_check_catches_a_part_that_jams():
    a = finalize(_flap_into_floor(), name="storage_box", seed=0, size=None, rng=item_rng(0, "y"))
    checks = {c.name: c for c in check_joints(a)}
    assert not checks["joint:flap_hinge"].passed and "did not reach" in checks["joint:flap_hinge"].detail


def test_joint_sweep_reaches_both_ends_of_a_drawer():
    a = generate("StorageFurniture", 3)
    checks = [c for c in check_joints(a) if c.name.startswith("joint:")]
    assert checks and all(c.passed for c in checks)
    assert all(np.isfinite(c.value) for c in checks)
