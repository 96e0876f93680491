"""Every container the knowledge base offers an object can take it: a proposal that names one must be
buildable (a 0.30 m plastic bag never lies in a bucket whose widest opening is 0.24 m)."""

from __future__ import annotations

import pytest

from anomalygen.assets.core import generate
from anomalygen.knowledge import load_kb
from anomalygen.scene.instances import container_room

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
