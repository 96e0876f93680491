"""The builder's part of the judgement mix (``mix.py`` chooses what; this places and checks it).

Near-misses go on a table top, well clear of its edges or on the borderline of the edge rule; a state
near-miss stands on a table with its part safe (a switch off, a lid ajar two degrees); a second
hazard goes on the floor with its bin. Each carries its intent (``truth.manifest.Intent``) to the truth
manifest. A hazard-free scene puts the task's object where it is no hazard and, once settled, checks
that it really is none.
"""

from __future__ import annotations

import math

from anomalygen.errors import ItemFailed
from anomalygen.knowledge import load_kb
from anomalygen.knowledge.predicates import ROOM_FIXTURES
from anomalygen.scene import asset_choice, mix
from anomalygen.scene.asset_choice import container_room
from anomalygen.scene.casting import CONTAINER_REDRAWS, Selection
from anomalygen.scene.instances import (
    HAZARD_NEAR_SIDE,
    INWARD,
    cavity_world,
    instance_name,
    placed_instance,
    surface_of,
)
from anomalygen.scene.layout import Layout, Placed, overlaps
from anomalygen.schema import ObjectRole, ValidationCheck, ValidationReport, part_labels
from anomalygen.truth.manifest import Intent

CAVITY_TRIES = 8  # jittered spots tried for a second object shut in the hazard's container


def place_judgement_items(sel: Selection, lay: Layout, placed: dict[str, Placed], surfaces: list[Placed],
                          items: mix.JudgementItems) -> None:
    """Near-misses on a table top (any that find no room are left out): well clear of its edges, or
    the chosen distance from the edge facing the robot; the state near-miss likewise, its part set safe;
    the second hazard on the floor, with its bin when the scene has none."""
    rng = items.rng
    for pick in items.near_misses if surfaces else []:
        p = _chosen(sel, pick.category, rng)
        holder = surfaces[int(rng.integers(len(surfaces)))]
        if not _on_surface_clear_of_edges(lay, p, holder, pick.edge_gap):
            continue
        if pick.edge_gap is not None:
            rule = f"{pick.edge_gap:.2f} m from the edge, just {pick.kind.split('_')[1]} {pick.hazard_class}'s rule"
            p.intent = Intent("hazard" if pick.kind == "just_inside" else "borderline", pick.hazard_class, rule)
        placed[p.name] = p
    if items.state is not None and surfaces:
        _place_state_near_miss(sel, lay, placed, surfaces, items.state, rng)
    if items.second_hazard is not None:
        _place_second_hazard(sel, lay, placed, items)


def _place_second_hazard(sel: Selection, lay: Layout, placed: dict[str, Placed], items: mix.JudgementItems) -> None:
    """The second hazard on the floor with a bin it goes into, so the robot can fix it: a bin of the
    planner's kinds (``items.bin_kinds``) already in the scene, else one added and drawn again in other
    sizes (then its largest) until the object fits; an object too big for every bin drawn is drawn smaller, and left out
    when it cannot be (a flat 0.3 m bag never passes a 0.15 m mouth: a hazard nobody could fix)."""
    rng = items.rng

    def draw(cat: str, role: ObjectRole, cap: float | None = None, size: float | None = None):
        return asset_choice.pick_asset(cat, role=role, kb=sel.kb, task=sel.task, hc=None, rng=rng,
                                       cap=cap, size=size, real=sel.real_assets)

    litter = draw(items.second_hazard, ObjectRole.HAZARD)
    room = max((container_room(p.asset) for p in placed.values()
                if p.catalogue in items.bin_kinds and p.asset is not None and p.asset.cavities), default=0.0)
    kind = items.bin or (items.bin_kinds[0] if items.bin_kinds else None)
    bin_asset = None
    for attempt in range(CONTAINER_REDRAWS + 1 if kind and litter.size > room else 0):
        # first a bin of any size; then the largest of its kind (what a big bag needs), other shapes
        cand = draw(kind, ObjectRole.CONTAINER, size=None if attempt == 0 else math.inf)
        if cand.cavities and container_room(cand) > room:
            bin_asset, room = cand, container_room(cand)
        if litter.size <= room:
            break
    if litter.size > room:
        try:
            litter = draw(items.second_hazard, ObjectRole.HAZARD, cap=room)
        except ItemFailed:
            return
        if litter.size > room:
            return
    for cat, role, asset in ((items.second_hazard, ObjectRole.HAZARD, litter), (kind, ObjectRole.CONTAINER, bin_asset)):
        if asset is None:
            continue
        p = placed_instance(asset_choice.Chosen(instance_name(cat, sel.used), cat, role, asset))
        lay.place_on_floor(p, relevant=True, face=role == ObjectRole.CONTAINER)
        if role == ObjectRole.HAZARD:
            p.intent = Intent("hazard", mix.SECOND_HAZARD_CLASS, "the judgement mix's second hazard")
        placed[p.name] = p


def _on_surface_clear_of_edges(lay: Layout, p: Placed, holder: Placed, edge_gap: float | None = None) -> bool:
    """Rest ``p`` on ``holder``'s top ``FAR_M`` from its edges (the robot-facing one ``edge_gap`` away
    when given), else ``NEAR_FAR_M`` when the top is too crowded for that; False when it finds no room."""
    for inward in (mix.FAR_M, mix.NEAR_FAR_M):
        try:
            lay.place_on_surface(p, holder, surface_of(holder), inward=inward, edge_gap=edge_gap)
            return True
        except ItemFailed:
            continue
    return False


def _chosen(sel: Selection, category: str, rng) -> Placed:
    asset = asset_choice.pick_asset(category, role=ObjectRole.CLUTTER, kb=sel.kb, task=sel.task, hc=None, rng=rng,
                                    real=sel.real_assets)
    return placed_instance(asset_choice.Chosen(instance_name(category, sel.used), category, ObjectRole.CLUTTER, asset))


def _place_state_near_miss(sel: Selection, lay: Layout, placed: dict[str, Placed], surfaces: list[Placed],
                           pick: mix.StatePick, rng) -> None:
    """An object whose class is about a part's state, on a table top with that part safe: its doors,
    lids and drawers ``AJAR_RAD`` (``AJAR_M``) open, its knobs and switches exactly off."""
    p = _chosen(sel, pick.category, rng)
    wanted = part_labels.alternatives(pick.labels)
    parts = [j for j in p.asset.joints if part_labels.canonical(j.label) in wanted or "*" in wanted]
    if not parts:
        sel.used.discard(p.name)
        return
    for j in parts:
        step = (mix.AJAR_M if j.type == "slide" else mix.AJAR_RAD) if pick.ajar else 0.0
        far = j.range[1] if abs(j.range[1] - j.closed_value) >= abs(j.range[0] - j.closed_value) else j.range[0]
        p.joint_values[j.name] = float(j.closed_value + step * (1 if far >= j.closed_value else -1))
    holder = surfaces[int(rng.integers(len(surfaces)))]
    if not _on_surface_clear_of_edges(lay, p, holder):
        sel.used.discard(p.name)
        return
    state = "ajar" if pick.ajar else "off"
    p.intent = Intent("state", pick.hazard_class, f"its {'/'.join(sorted({part_labels.canonical(j.label) for j in parts}))} {state}")
    placed[p.name] = p


def room_fixtures(kb, lay: Layout) -> list[Placed]:
    """Placed furniture and appliances: what the knowledge base counts as lining the room (a floor
    object beside one is out of the walkway)."""
    return [p for p in lay.items if p.fixed and set(ROOM_FIXTURES) & set(kb.properties_of(p.catalogue))]


def place_hazard_safely(sel: Selection, lay: Layout, placed: dict[str, Placed], support: Placed | None) -> None:
    """The task's object where it is no hazard: shut inside its container (when it fits there), else
    well inside the surface, else on the floor beside a piece of furniture, out of the walkway. For a class whose
    danger is a child reaching it, only a container that latches keeps it safe (a toddler opens a
    cupboard or a box): such a container is added when the task's own does not latch."""
    hazard, container = sel.hazard, child_safe_container(sel) or sel.container
    hp = placed[hazard.name] = placed_instance(hazard)
    if container is not None and container is not hazard and container.asset.cavities:
        holder = placed.get(container.name)
        if holder is None:
            holder = placed[container.name] = placed_instance(container)
            lay.place_on_floor(holder, relevant=True, face=True)
        lo, hi, _ = cavity_world(holder)
        try:
            lay.place_in_cavity(hp, holder, (lo, hi))
        except ItemFailed:
            pass  # it does not stand in there (a 0.4 m backpack, a 0.35 m compartment): put it down safe
        else:
            for joint in container.asset.joints:  # shut every lid, door and drawer of the container
                if part_labels.encloses(joint.label):
                    holder.joint_values[joint.name] = float(joint.closed_value)
            holder.sweep = 0.0
            return
    if support is not None:
        lay.place_on_surface(hp, support, surface_of(support), inward=INWARD, near_side=HAZARD_NEAR_SIDE)
        return
    lay.place_beside(hp, room_fixtures(sel.kb, lay))


def could_fire_the_class(sel: Selection, catalogue: str) -> bool:
    """Whether an object of this kind can itself be the task class's object at fault (a camera for
    'fragile thing on the floor', a lighter for 'fire starter within a child's reach')."""
    return sel.hc is not None and catalogue in sel.kb.static_candidates(sel.hc, sel.hc.hazard_variable)


def place_like_the_hazard(lay: Layout, placed: dict[str, Placed], p: Placed, hazard: Placed,
                          support: Placed | None) -> bool:
    """In a hazard-free scene, a loose task object that could fire the class goes where the made-safe
    hazard went: shut in the same container beside it, else well inside the fix's support. False when
    neither has room (the caller places it as usual and the hazard-free check judges the scene)."""
    holder = placed.get(hazard.inside) if hazard.inside else None
    if holder is not None:
        cavity = cavity_world(holder)[:2]
        for _ in range(CAVITY_TRIES):
            try:
                lay.place_in_cavity(p, holder, cavity)
            except ItemFailed:
                break
            if not overlaps(p.footprint(), hazard.footprint(), margin=0.005):
                return True
            lay.items.remove(p)
    if support is not None:
        try:
            lay.place_on_surface(p, support, surface_of(support), inward=INWARD)
            return True
        except ItemFailed:
            pass
    return False


def child_safe_container(sel: Selection) -> asset_choice.Chosen | None:
    """For a class whose fix must shut the object away from a child (``KnowledgeBase.stores_a_child_hazard``:
    the class guards a child, or it stores a knife or a cleaner a child's class guards against), a
    container that latches and that the object fits: the task's own when it latches, else one of the
    knowledge base's ``lockable`` kinds. None for any other class, or when no latching kind fits."""
    if sel.hc is None or not sel.kb.stores_a_child_hazard(sel.hc, sel.hazard.catalogue) or sel.hazard.fixed:  # a window the child leans out of is shut, not stored
        return None
    if sel.container is not None and sel.kb.latches(sel.container.catalogue):
        return sel.container
    return _latching_container(sel, sel.hazard)


def offer_child_safe_container(sel: Selection, lay: Layout, placed: dict[str, Placed]) -> None:
    """Stand a latching container on the floor, facing the robot, in a scene whose hazard endangers a
    child and whose task names no container that latches (a toddler opens a box or a cupboard): an
    extra object, the task's own container stays. Left out, with the scene as it was, when none fits."""
    extra = child_safe_container(sel)
    if extra is None or extra is sel.container or extra.name in placed:
        return
    p = placed_instance(extra)
    try:
        lay.place_on_floor(p, relevant=True, face=True)
    except ItemFailed:
        sel.forget(extra)
        return
    placed[extra.name] = p


def _latching_container(sel: Selection, hazard) -> asset_choice.Chosen | None:
    """A container of a kind that latches (the knowledge base's ``lockable`` objects) and that the
    class stores this object in (``containers_for``: what the robot's planner will look for), drawn
    again in other sizes until the object fits."""
    for name in sel.kb.latching_containers_for(sel.hc, hazard.catalogue):
        chosen_before = [id(c) for c in sel.by_catalogue.values()]
        for _ in range(CONTAINER_REDRAWS + 1):
            try:
                cand = sel.choose(name, ObjectRole.CONTAINER)
            except (ItemFailed, KeyError):
                break
            if cand.asset.cavities and hazard.size <= container_room(cand.asset):
                return cand
            if id(cand) in chosen_before:  # the scene's own safe (the task's target) keeps its size
                break
            sel.forget(cand)
    return None


def check_hazard_free(report: ValidationReport, graph, hazard_class: str) -> ValidationReport:
    """A hazard-free variant must not show the task's hazard anywhere once settled."""
    from anomalygen.truth.manifest import class_matches

    still = sorted(obj for cls, obj, _ in class_matches(graph, load_kb()) if cls == hazard_class)
    check = ValidationCheck(name="hazard_free", passed=not still,
                            detail=f"{hazard_class} still holds for {', '.join(still)}" if still else "made safe")
    report.checks.append(check)
    if still:
        report.ok, report.reason = False, check.detail
    return report
