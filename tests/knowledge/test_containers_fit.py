"""Every container the knowledge base offers an object can take it: a proposal that names one must be
buildable (a 0.30 m plastic bag never lies in a bucket whose widest opening is 0.24 m)."""

from __future__ import annotations

import pytest

from anomalygen.assets.core import generate
from anomalygen.knowledge import load_kb
from anomalygen.scene.asset_choice import container_room

SEEDS = range(4)  # generator variants of a container at its largest size; the roomiest one counts
# Cables are laid along a wall, never stored (clear_cable_from_walkway has no container), and a coiled
# cable is not modelled: its length is no measure of what it needs in a box.
NOT_RIGID = "cable"


def _roomiest(kb, catalogue: str) -> float | None:
    largest = kb.objects[catalogue].size_range[1]
    rooms = [container_room(a) for s in SEEDS if (a := generate(catalogue, s, size=largest)).cavities]
    return max(rooms) if rooms else None


def test_each_objects_containers_can_hold_it_at_its_smallest():
    kb = load_kb()
    roomiest: dict[str, float | None] = {}
    too_small = []
    for name, info in kb.objects.items():
        if NOT_RIGID in info.properties:
            continue
        for container in info.containers:
            if container not in roomiest:
                roomiest[container] = _roomiest(kb, container)
            room = roomiest[container]
            if room is not None and room < info.size_range[0]:
                too_small.append(f"{name} (>= {info.size_range[0]} m) in {container} (<= {room:.2f} m)")
    assert not too_small, too_small


@pytest.mark.parametrize("container", ["Bucket", "basket"])
def test_the_check_sees_a_containers_real_opening(container):
    kb = load_kb()
    assert 0.1 < _roomiest(kb, container) < kb.objects[container].size_range[1]


def test_a_class_that_guards_a_child_offers_only_containers_that_latch():
    """The brainstormed fix must end the hazard: a knife "locked in the storage box" is still a
    toddler's; the litter class, which guards no child, keeps its open bins."""
    kb = load_kb()
    sharp, litter = kb.hazard_classes["keep_sharp_away_from_children"], kb.hazard_classes["pick_up_floor_litter"]
    assert kb.guards_a_child(sharp) and not kb.guards_a_child(litter)
    assert "storage_box" in kb.containers_for(sharp, "Knife")
    assert kb.safe_containers_for(sharp, "Knife") == ["Safe"] and kb.latches("Safe")
    assert kb.safe_containers_for(litter, "wrapper") == kb.containers_for(litter, "wrapper")


@pytest.mark.parametrize(("cls", "obj", "child_cls"), [
    ("store_sharp_objects", "kitchen_knife", "keep_sharp_away_from_children"),
    ("manage_chemical_risks", "bleach_bottle", "keep_chemicals_from_children"),
    ("separate_chemical_from_food", "cleaning_spray", "keep_chemicals_from_children"),
])
def test_a_class_that_stores_a_childs_hazard_for_an_adult_adds_the_childs_latching_kinds(cls, obj, child_cls):
    """Issue 23's leftover: a knife or a bleach bottle put away low in a box a toddler opens fires the
    child's class, so the referee rejects the fix. The class keeps its own kinds and gains the latching
    ones of the child's class, which the builder offers and the brainstormed text promises."""
    kb = load_kb()
    hc, child = kb.hazard_classes[cls], kb.hazard_classes[child_cls]
    assert not kb.guards_a_child(hc) and kb.stores_a_child_hazard(hc, obj)
    own = [c for c in hc.default_containers if c in kb.objects[obj].containers] or hc.default_containers
    latching = [k for k in kb.containers_for(child, obj) if kb.latches(k)]
    assert latching and kb.containers_for(hc, obj) == [*own, *latching]
    assert kb.safe_containers_for(hc, obj) == kb.latching_containers_for(hc, obj) == latching
    tripping = kb.hazard_classes["reduce_tripping_hazards"]  # a shoe is nobody's toddler hazard
    assert not kb.stores_a_child_hazard(tripping, "shoe")
    assert kb.safe_containers_for(tripping, "shoe") == kb.containers_for(tripping, "shoe")
