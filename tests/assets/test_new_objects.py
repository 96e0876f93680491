"""The open-world hazard objects (issue 25): real sizes and masses, the controls and closures a
hazard is about with their safe values, the surfaces and cavities things go on and in, and every one
passes the physical validation."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from anomalygen.assets import generate, household_names, size_range, validate_asset
from anomalygen.schema import CLOSURE_LABELS, SWITCH_LABELS

NEW = ["Stove", "Sink", "Bathtub", "SpaceHeater", "PowerStrip", "Curtains", "Crib", "Stairs", "Bookcase",
       "BabyGate", "PaperTowels", "Blanket"]
UPGRADED = ["iron", "hair_dryer", "candle"]  # existing names that gained an on/off control
# name -> (mass range kg, the labels of its joints)
FACTS = {
    "Stove": ((35, 70), ["knob"] * 4),
    "Sink": ((40, 120), ["tap"]),
    "Bathtub": ((40, 90), ["tap"]),
    "SpaceHeater": ((1.5, 8), ["knob"]),
    "PowerStrip": ((0.2, 1.0), ["switch"]),
    "Curtains": ((8, 30), []),
    "Crib": ((20, 45), []),
    "Stairs": ((25, 80), []),
    "Bookcase": ((25, 60), []),
    "BabyGate": ((2, 8), ["gate"]),
    "PaperTowels": ((0.2, 0.8), []),
    "Blanket": ((0.8, 3.5), []),
    "iron": ((1, 6), ["switch"]),
    "hair_dryer": ((0.2, 0.8), ["switch"]),
    "candle": ((0.1, 1), ["switch"]),
}


def test_new_names_are_household_vocabulary():
    assert set(NEW) <= set(household_names())


@pytest.mark.parametrize("name", NEW + UPGRADED)
def test_size_mass_and_joints(name):
    (m_lo, m_hi), labels = FACTS[name]
    lo, hi = size_range(name)
    for seed in range(3):
        a = generate(name, seed)
        assert lo <= a.size <= hi and a.params["size"] == pytest.approx(a.size, rel=1e-3)
        assert m_lo <= a.mass <= m_hi, (seed, a.mass)
        assert sorted(j.label for j in a.joints) == sorted(labels)
        for j in a.joints:
            # off / closed is the joint's end at 0: a scene built without asking for "on" is off
            assert j.closed_value == 0.0 and 0.0 in (min(j.range), max(j.range))
            assert j.label in SWITCH_LABELS or j.label in CLOSURE_LABELS


def test_stove_has_a_knob_and_a_surface_per_burner_at_counter_height():
    a = generate("Stove", 2)
    burners = [s for s in a.surfaces if s.name.startswith("burner_")]
    knobs = {j.body for j in a.joints}
    assert len(burners) == 4 and knobs == {f"knob_{k}" for k in range(4)}
    assert all(0.85 <= s.center[2] <= 0.95 for s in burners)
    for j in a.joints:  # every knob faces the front, where the robot stands
        assert j.axis == (0.0, -1.0, 0.0) and j.range == (0.0, 4.7)


@pytest.mark.parametrize("name", ["Sink", "Bathtub"])
def test_basins_hold_water_and_have_a_tap(name):
    a = generate(name, 1)
    (basin,) = a.cavities
    assert basin.opening == "top" and basin.joint is None and basin.open_above
    assert min(basin.half_extents) > 0.06
    model = a.spec.copy().compile()
    water = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "water")
    assert water >= 0 and model.geom_rgba[water, 3] == 0.0  # hidden until the builder fills it
    assert model.geom_contype[water] == 0 and model.geom_conaffinity[water] == 0
    (tap,) = a.joints
    assert tap.label == "tap" and tap.type == "hinge" and tap.range == (-0.6, 0.0)


def test_bookcase_high_shelf_stairs_crib_and_gate():
    for seed in range(4):
        boards = [s for s in generate("Bookcase", seed).surfaces if s.name.startswith("board_")]
        assert max(s.center[2] for s in boards) >= 1.4
        # listed from the top down: a holder's largest surface is its first, so "on the bookcase" is the high shelf
        assert boards[0].center[2] == max(s.center[2] for s in boards)
    steps = generate("Stairs", 0).surfaces
    rises = np.diff([s.center[2] for s in steps])
    assert len(steps) >= 3 and np.all((rises > 0.15) & (rises < 0.2))
    crib = generate("Crib", 0)
    assert crib.cavities[0].open_above and 0.25 <= crib.surfaces[0].center[2] <= 0.5
    gate = generate("BabyGate", 0).joints[0]
    assert gate.label == "gate" and abs(gate.axis[2]) == 1.0 and math.degrees(max(abs(v) for v in gate.range)) > 90


@pytest.mark.parametrize("name", NEW + UPGRADED)
def test_validates(name):
    res = validate_asset(generate(name, 0), render=False)
    assert res.ok, res.reason


@pytest.mark.parametrize("name", ["PowerStrip", "iron", "hair_dryer", "candle"])
def test_push_switches_stay_on_and_stop_at_off_when_pressed(name):
    """A push switch (a candle's snuffer too) stands proud when on and stays so; pressed down hard from
    above it stops at off instead of being driven through its end stop (which reads as on again)."""
    a = generate(name, 1)
    (j,) = a.joints
    assert j.type == "slide" and j.axis == (0.0, 0.0, 1.0) and j.range[0] == 0.0
    model = a.spec.copy().compile()
    data = mujoco.MjData(model)
    adr = model.jnt_qposadr[model.joint(j.name).id]
    travel = j.range[1]
    data.qpos[adr] = 0.8 * travel
    mujoco.mj_step(model, data, nstep=2000)  # 4 s
    assert data.qpos[adr] > 0.75 * travel
    data.xfrc_applied[model.body(j.body).id, 2] = -20.0  # a firm press, 20 N
    mujoco.mj_step(model, data, nstep=250)
    assert abs(data.qpos[adr]) < 0.03 * travel
    data.xfrc_applied[:] = 0.0
    mujoco.mj_step(model, data, nstep=250)
    assert abs(data.qpos[adr]) < 0.03 * travel  # let go, it stays off
