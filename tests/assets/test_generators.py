"""The Asset contract and the semantics of the procedural generators (fast: no simulation)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from anomalygen.assets import Asset, from_ref, generate, household_names, size_range, target_names
from anomalygen.assets.core import available_names

# Articulation labels each category must expose (issue 4's list).
REQUIRED_LABELS = {
    "StorageFurniture": {"door|drawer"},
    "Refrigerator": {"door"},
    "Oven": {"door", "knob"},
    "Dishwasher": {"door", "rack"},
    "Microwave": {"door"},
    "WashingMachine": {"door|lid"},
    "Safe": {"door"},
    "Door": {"door"},
    "Window": {"sash"},
    "Box": {"lid|flap"},
    "Suitcase": {"lid"},
    "Kettle": {"lid"},
    "KitchenPot": {"lid"},
    "Lighter": {"lid"},
    "TrashCan": {"lid"},
    "Toilet": {"lid", "seat"},
    "Laptop": {"hinge"},
    "Scissors": {"blade"},
    "Pliers": {"handle"},
    "Knife": {"blade"},
    "Stapler": {"lid"},
    "Lamp": {"arm"},
    "Fan": {"rotor"},
    "Globe": {"spin"},
    "Clock": {"hand"},
    "Cart": {"wheel"},
    "Chair": {"backrest"},
    "FoldingChair": {"seat"},
    "Eyeglasses": {"temple"},
    "USB": {"cap"},
    "Pen": {"cap|button"},
}


def test_every_vocabulary_name_has_a_generator_and_enough_household_objects():
    assert len(target_names()) == 44
    names = set(available_names())
    assert set(target_names()) <= names and set(household_names()) <= names
    rigid = [n for n in household_names() if not generate(n, 0).joints]
    assert len(rigid) >= 60


def test_asset_contract_root_body_radians_and_centred_bottom():
    a = generate("Refrigerator", 3)
    assert isinstance(a, Asset)
    assert a.spec.compiler.degree is False or a.spec.compiler.degree == 0
    bodies = [b for b in a.spec.worldbody.bodies]
    assert [b.name for b in bodies] == ["root"]
    assert not any(j.type == mujoco.mjtJoint.mjJNT_FREE for j in a.spec.joints)
    lo, hi = a.aabb
    assert lo[2] == pytest.approx(0.0) and lo[0] == pytest.approx(-hi[0]) and lo[1] == pytest.approx(-hi[1])
    model = a.spec.copy().compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    # the compiled geometry really sits on z = 0 and matches the analytic box
    zmin = min(data.geom_xpos[g][2] - model.geom_rbound[g] for g in range(model.ngeom))
    assert zmin <= 0.02
    for j in a.joints:
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j.name)
        assert tuple(model.jnt_range[jid]) == pytest.approx(j.range)  # radians, not degrees
        assert min(j.range) - 1e-9 <= j.closed_value <= max(j.range) + 1e-9
    assert a.mass == pytest.approx(float(model.body_subtreemass[1]), rel=0.02)


def test_size_is_clamped_to_the_plausible_range_and_scales_uniformly():
    lo, hi = size_range("pill_bottle")
    big = generate("pill_bottle", 1, size=10.0)
    small = generate("pill_bottle", 1, size=0.001)
    assert big.size == pytest.approx(hi, rel=1e-6) and small.size == pytest.approx(lo, rel=1e-6)
    mid = generate("pill_bottle", 1, size=(lo + hi) / 2)
    assert mid.mass / small.mass == pytest.approx((mid.size / small.size) ** 3, rel=1e-6)


def test_seeded_variants_are_deterministic_and_distinct():
    a1, a2, b = (
        generate("StorageFurniture", 5),
        generate("StorageFurniture", 5),
        generate("StorageFurniture", 6),
    )
    assert a1.spec.to_xml() == a2.spec.to_xml() and a1.description == a2.description
    layouts = {
        (generate("StorageFurniture", s).params["cols"], generate("StorageFurniture", s).params["rows"])
        for s in range(12)
    }
    assert len(layouts) >= 4
    assert a1.spec.to_xml() != b.spec.to_xml()
    counts = {len(generate("StorageFurniture", s).joints) for s in range(20)}
    assert min(counts) >= 1 and max(counts) <= 6 and len(counts) >= 3


@pytest.mark.parametrize("name", sorted(REQUIRED_LABELS))
def test_required_articulations(name):
    seen = set()
    for seed in range(4):
        seen |= {j.label for j in generate(name, seed).joints}
    for need in REQUIRED_LABELS[name]:
        assert seen & set(need.split("|")), f"{name} lacks {need}: {seen}"


def test_refrigerator_has_freezer_and_a_fridge_cavity_closed_by_a_door():
    for seed in range(4):
        a = generate("Refrigerator", seed)
        names = {c.name: c for c in a.cavities}
        assert {"fridge", "freezer"} <= set(names)
        joints = {j.name for j in a.joints}
        assert names["fridge"].joint in joints and names["freezer"].joint in joints
        lo, hi = a.aabb
        for c in a.cavities:
            assert np.all(np.asarray(c.center) - c.half_extents >= lo - 1e-6) and np.all(
                np.asarray(c.center) + c.half_extents <= hi + 1e-6
            )


def test_counter_of_a_requested_size_keeps_counter_height():
    # a 2.3 m counter is longer, not taller: scaled uniformly it stood 1.46 m high, out of the arm's reach
    for size in (1.0, 1.8, 2.3):
        c = generate("counter", 418056419, size=size)
        assert c.size == pytest.approx(size, abs=1e-3)
        assert 0.85 < c.surfaces[0].center[2] < 0.93 and c.aabb[1][2] < 0.93
        assert c.aabb[1][1] - c.aabb[0][1] < 0.7  # about 0.6 m deep


def test_furniture_surfaces_and_cavities():
    counter = generate("counter", 0)
    top = counter.surfaces[0]
    assert 0.8 < top.center[2] < 1.0 and top.center[2] == pytest.approx(counter.aabb[1][2], abs=0.01)
    shelf = generate("shelf", 2)
    assert len(shelf.surfaces) >= 3 and sorted(s.center[2] for s in shelf.surfaces) == [
        s.center[2] for s in shelf.surfaces
    ]
    med = generate("medicine_cabinet", 0)
    assert med.cavities and all(c.joint == "door_hinge" and c.opening == "front" for c in med.cavities)
    assert generate("storage_box", 0).cavities[0].joint == "lid_hinge"
    cab = generate("StorageFurniture", 4)
    drawer_bins = [c for c in cab.cavities if c.opening == "top"]
    for c in drawer_bins:
        assert c.joint and c.joint.endswith("_slide")


def test_attach_twice_into_a_scene_with_prefixes():
    scene = mujoco.MjSpec()
    knife = generate("Knife", 0)
    body = knife.attach(scene.worldbody, "k0_")
    knife.attach(scene.worldbody.add_body(name="table"), "k1_")
    assert body.name == "k0_root"
    model = scene.compile()
    names = {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, i) for i in range(model.njnt)}
    assert names == {"k0_blade_hinge", "k1_blade_hinge"}
    assert model.jnt_range[0][1] == pytest.approx(math.pi)  # radians survive a degree-default parent
    knife.spec.compile()  # the asset's own spec stays usable after attaching


def test_descriptions_carry_size_and_hazards():
    assert "choke" in generate("marble", 0).description
    assert "sharp" in generate("kitchen_knife", 0).description
    assert "medicine" in generate("pill_bottle", 0).description
    assert "door" in generate("Refrigerator", 0).description


def test_ref_round_trip_rebuilds_the_same_asset():
    a = generate("Oven", 4, size=0.7)
    b = from_ref(a.ref)
    assert b.spec.to_xml() == a.spec.to_xml() and b.size == pytest.approx(0.7)
    assert a.ref.model_dump()["category"] == "Oven"
