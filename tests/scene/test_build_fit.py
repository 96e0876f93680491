"""The builder binds only a container the hazard can lie in, or fails the item saying it does not fit.

``build._plan`` is the selection-and-placement half of one build attempt (no MuJoCo compile), so each
attempt's choice is checked directly; ``item_rng(seed, task.id, attempt)`` is the generator
``build._attempt`` hands it, so attempts 0..repair_attempts are exactly the ones a build makes.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from anomalygen.config import Settings
from anomalygen.errors import ItemFailed
from anomalygen.rng import item_rng
from anomalygen.scene import asset_choice, build
from anomalygen.schema import TaskProposal

ATTEMPTS = 4  # a build makes repair_attempts + 1 = 4 by default


def _litter(hazard: str, container: str, target: str) -> TaskProposal:
    return TaskProposal(
        id=f"t-fit-{hazard}-{container}-{target}", name="litter", explanation="test",
        description=f"A {hazard} lies in the walkway.", category="household_hazard",
        hazard_class="pick_up_floor_litter", target_asset=target,
        scenario=dict(hazard_object=hazard, room="office", placement="walkway", container=container, co_objects=[]),
        provenance=dict(engine="knowledge", mode="brainstorm"))


SETTINGS = Settings(build={"clutter": 0, "repair_attempts": ATTEMPTS - 1})


def _outcomes(task: TaskProposal, attempts: int = ATTEMPTS):
    """Per attempt: ('fit', hazard size, room of the placed container) or ('failed', message)."""
    out = []
    for attempt in range(attempts):
        try:
            _, bindings, placed = build._plan(task, SETTINGS, item_rng(0, task.id, attempt))
        except ItemFailed as exc:
            out.append(("failed", str(exc)))
            continue
        hazard, container = placed[bindings["$hazard"]], placed[bindings["$container"]]
        out.append(("fit", float(hazard.asset.size), asset_choice.container_room(container.asset)))
    return out


def _assert_fits_or_says_so(outcomes):
    for k, o in enumerate(outcomes):
        if o[0] == "fit":
            assert o[1] <= o[2] + 1e-9, f"attempt {k}: a {o[1]:.3f} m hazard bound to a container with {o[2]:.3f} m room"
        else:
            assert "does not fit" in o[1], f"attempt {k}: {o[1]}"


def test_container_room_is_the_long_side_of_the_biggest_cavity():
    from anomalygen.assets.core import generate

    for name in ("Bucket", "storage_box", "StorageFurniture"):
        asset = generate(name, 0)
        cav = max(asset.cavities, key=lambda c: float(np.prod(c.half_extents)))
        room = asset_choice.container_room(asset)
        assert room == pytest.approx(0.95 * 2 * max(cav.half_extents[0], cav.half_extents[1]))
        # it lies inside the object's own footprint
        ext = np.asarray(asset.aabb[1]) - np.asarray(asset.aabb[0])
        assert 0.05 < room < max(ext[0], ext[1])
    # a bigger bucket has more room; the generator scales the cavity with the asset
    small, big = generate("Bucket", 3, size=0.25), generate("Bucket", 3, size=0.4)
    assert asset_choice.container_room(small) < asset_choice.container_room(big)
    assert asset_choice.container_room(big) / asset_choice.container_room(small) == pytest.approx(0.4 / 0.25, rel=0.15)


def test_bag_and_bucket_fail_with_does_not_fit_after_redrawing_the_bucket(monkeypatch, tmp_path):
    """No bucket (at most ~0.24 m of room) takes a plastic bag (at least 0.30 m). The bucket is also the
    task's target, so it keeps its draw; the bag is drawn smaller and the item fails saying so."""
    task = _litter("plastic_bag", "Bucket", "Bucket")
    drawn: list = []
    real = asset_choice.pick_asset

    def counting(catalogue, **kw):
        asset = real(catalogue, **kw)
        drawn.append((catalogue, asset))
        return asset

    monkeypatch.setattr(asset_choice, "pick_asset", counting)
    outcomes = _outcomes(task)
    _assert_fits_or_says_so(outcomes)
    assert all(o[0] == "failed" for o in outcomes)
    # one attempt: the bucket drawn once (it is the target), then the bag with the bucket's room as cap
    drawn.clear()
    with pytest.raises(ItemFailed) as exc:
        build._plan(task, SETTINGS, item_rng(0, task.id, 0))
    buckets = [a for c, a in drawn if c == "Bucket"]
    assert len(buckets) == 1
    cap = float(re.search(r"does not fit a ([0-9.]+) m space", str(exc.value)).group(1))
    assert cap == pytest.approx(asset_choice.container_room(buckets[-1]), abs=0.006)
    # the whole build fails with the same reason (selection fails before anything is compiled)
    once = Settings(build={"clutter": 0, "repair_attempts": 0})
    with pytest.raises(ItemFailed, match="does not fit"):
        build.build_scene(task, seed=0, settings=once, out_dir=tmp_path / "scene")
    assert not (tmp_path / "scene" / "scene.json").exists()


def test_container_redrawn_until_the_hazard_fits():
    """Target elsewhere (a table): buckets are redrawn or the wrapper drawn smaller until it fits."""
    outcomes = _outcomes(_litter("wrapper", "Bucket", "Table"))
    _assert_fits_or_says_so(outcomes)
    assert any(o[0] == "fit" for o in outcomes)


def test_container_that_is_also_the_target_fits_the_hazard():
    """The target container keeps its draw; the hazard is drawn smaller or the item says it cannot fit."""
    _assert_fits_or_says_so(_outcomes(_litter("wrapper", "Bucket", "Bucket")))


def test_hazard_that_is_the_target_fits_or_fails():
    _assert_fits_or_says_so(_outcomes(_litter("plastic_bag", "TrashCan", "plastic_bag")))


def test_a_named_container_is_never_swapped_for_a_roomier_kind():
    """The task says "the bucket" and the bucket's target is a chair: no trash can stands in for the
    bucket; every attempt fails, naming the bucket and the class's other containers."""
    outcomes = _outcomes(_litter("plastic_bag", "Bucket", "Chair"))
    assert all(o[0] == "failed" for o in outcomes), outcomes
    for _, message in outcomes:
        assert "does not fit" in message and "names the Bucket" in message and "TrashCan" in message


def _open_drawer(target: str, hazard: str) -> TaskProposal:
    return TaskProposal(
        id=f"t-part-{target}-{hazard}", name="open drawer", explanation="test",
        description=f"The {hazard} was left open.", category="child_safety",
        hazard_class="close_open_furniture", target_asset=target,
        scenario=dict(hazard_object=hazard, room="bedroom", placement="floor", co_objects=[]),
        provenance=dict(engine="knowledge", mode="brainstorm"))


def test_a_table_whose_drawer_is_the_hazard_is_drawn_with_a_drawer():
    """One procedural table in three has a drawer: the draws go on until one has it."""
    task = _open_drawer("Table", "Table")
    for attempt in range(6):
        _, bindings, placed = build._plan(task, SETTINGS, item_rng(0, task.id, attempt))
        table = placed[bindings["$target"]]
        assert asset_choice.joints_with_label(table.asset, "drawer"), f"attempt {attempt}: a table without a drawer"


def test_a_task_naming_another_object_at_fault_than_its_target_is_refused():
    """Built, the open drawer would be the table's while the task speaks of the safe."""
    with pytest.raises(ItemFailed, match="about the target itself"):
        build._plan(_open_drawer("Table", "Safe"), SETTINGS, item_rng(0, "x", 0))


def _crib_strip() -> TaskProposal:
    return TaskProposal(
        id="t-fit-strip-safe", name="strip by the crib", explanation="test",
        description="A power strip lies beside the crib.", category="child_safety",
        hazard_class="cable_near_crib", target_asset="Safe",
        scenario=dict(hazard_object="PowerStrip", room="bedroom", placement="near:Crib", container="Safe",
                      co_objects=["Crib"]),
        provenance=dict(engine="knowledge", mode="brainstorm"))


def test_target_container_is_drawn_with_room_for_the_hazard():
    """The safe is the task's target, so it keeps its draw: it is drawn with room for the smallest
    power strip (0.30 m; a 0.3 m safe holds 0.18-0.23 m). Before, 3 safes in 4 were too small and the
    item failed "does not fit ... the task names the Safe"."""
    task = _crib_strip()
    from anomalygen.knowledge import load_kb

    least = asset_choice.size_bounds(load_kb(), "PowerStrip")[0]
    outcomes = _outcomes(task)
    fits = [o for o in outcomes if o[0] == "fit"]
    assert len(fits) >= 3 and all(o[1] <= o[2] and o[2] >= least for o in fits), outcomes
    # an attempt may still fail (no base pose reaches the strip), never for want of room
    assert not [o for o in outcomes if o[0] == "failed" and "does not fit" in o[1]], outcomes


def test_an_object_put_in_through_a_front_door_lies_in_the_front_half():
    """t0034 of the seed-0 loop at 8b4be29: a detergent pod at the back of a fridge's lowest
    compartment, 0.4 m past the opening, where the arm cannot reach (it gets 0.33-0.36 m in, past the
    shelf above). An object placed inside a front-opening cavity now lies in its front half."""
    from anomalygen.scene.instances import cavity_front, cavity_world

    task = TaskProposal(
        id="t-fit-pod-fridge", name="pod in the fridge", explanation="test",
        description="A detergent pod lies in the fridge.", category="household_hazard",
        hazard_class="remove_chemical_from_fridge", target_asset="Refrigerator",
        scenario=dict(hazard_object="detergent_pod", room="kitchen", placement="inside:Refrigerator",
                      container="Safe", co_objects=[]),
        provenance=dict(engine="knowledge", mode="brainstorm"))
    depths = []
    for seed in range(6):
        _, bindings, placed = build._plan(task, SETTINGS, item_rng(seed, task.id, 0))
        pod = placed[bindings["$hazard"]]
        fridge = placed[pod.inside]
        lo, hi, cav = cavity_world(fridge)
        front = cavity_front(fridge, cav)
        assert front is not None
        k = int(np.argmax(np.abs(front[:2])))
        mouth = hi[k] if front[k] > 0 else lo[k]
        depth = abs(mouth - pod.world_center()[k])
        assert depth <= (hi[k] - lo[k]) / 2 + 1e-6, f"seed {seed}: the pod's centre lies {depth:.2f} m past the opening"
        depths.append(depth)
    assert len({round(d, 3) for d in depths}) > 1  # still drawn, not pinned to one spot


def test_a_trash_can_named_for_a_plastic_bag_is_drawn_roomy_enough():
    """A 0.30 m bag fits only the roomiest trash cans (about 0.7 m tall). The generator checks that
    size exists; the builder draws it: a cramped draw makes the next aim at the size whose room holds
    the bag, so the bin task builds at every attempt instead of failing "does not fit"."""
    task = _litter("plastic_bag", "TrashCan", "TrashCan")
    outcomes = _outcomes(task)
    _assert_fits_or_says_so(outcomes)
    assert all(o[0] == "fit" for o in outcomes), outcomes


def test_a_repair_draws_the_object_at_fault_smaller():
    """Attempt k draws the object at fault from the lower 1/(k+1)^2 of its range: a cord too long for
    the table it lies on is drawn shorter, not again at random."""
    from anomalygen.knowledge import load_kb

    kb = load_kb()
    lo, hi = asset_choice.size_bounds(kb, "extension_cord")
    task = TaskProposal(
        id="t-fit-cord", name="cord", explanation="test", description="An extension cord lies across the hall.",
        category="household_hazard", hazard_class="clear_cable_from_walkway", target_asset="extension_cord",
        scenario=dict(hazard_object="extension_cord", room="hallway", placement="walkway", co_objects=[]),
        provenance=dict(engine="knowledge", mode="brainstorm"))
    from anomalygen.scene.casting import select_objects

    sizes = []
    for attempt in range(ATTEMPTS):
        sel = select_objects(task, item_rng(0, task.id, attempt), repair=attempt)
        sizes.append(float(sel.hazard.size))
        assert lo - 1e-9 <= sizes[-1] <= lo + (hi - lo) / (attempt + 1) ** 2 + 1e-9, (attempt, sizes)
    assert sizes[-1] < lo + 0.1 * (hi - lo)
