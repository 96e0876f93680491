"""Where every chosen object stands: supports, furniture, the hazard, loose task objects, clutter.

``place`` lays out a ``selection.Selection`` with ``layout.Layout`` (the hazard where its scenario says,
or safely for a hazard-free scene), checks that the robot can reach the hazard from some free base
pose, and then starts the robot at its dock, which does not depend on the hazard (``build.start``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from anomalygen.errors import ItemFailed
from anomalygen.scene import asset_choice, furniture, mix
from anomalygen.scene.casting import Selection, clutter_names
from anomalygen.scene.instances import (
    HAZARD_NEAR_SIDE,
    INWARD,
    cavity_front,
    cavity_world,
    instance_name,
    placed_instance,
    placed_support,
    surface_of,
)
from anomalygen.scene.judgement import (
    could_fire_the_class,
    offer_child_safe_container,
    place_hazard_safely,
    place_judgement_items,
    place_like_the_hazard,
    room_fixtures,
)
from anomalygen.scene.layout import Layout, Placed, face_robot_yaw, reached_from_front
from anomalygen.schema import ObjectRole

if TYPE_CHECKING:
    from anomalygen.config import Settings


NEAR_GAP = (0.03, 0.12)  # m between a 'near:<name>' hazard and that object (the knowledge base's near: <= 0.2-0.3)
LOOSE_ON_SUPPORT_MAX = 0.35  # m: a loose task object smaller than this goes on the support, not the floor
FACING_TRIES = 16  # draws of a parent's spot on its support until its door faces the robot


def place(sel: Selection, settings: Settings) -> tuple[Layout, dict[str, Placed], Placed | None]:
    """Place every chosen object (and the clutter) in the room; returns the layout, the placed
    objects by name and the support the hazard stands on (if any)."""
    rng, used = sel.rng, sel.used
    target, parent, hazard = sel.target, sel.parent, sel.hazard
    support_kind = sel.placement.furniture  # the table, counter or shelf it is on or at the edge of
    lay = Layout(rng, relevant_in_cube=settings.build.relevant_in_unit_cube)
    if sel.hints is not None:
        for ch in sel.by_catalogue.values():
            xy = sel.hints.world_xy(ch.catalogue)
            if xy is not None:
                lay.preferred[ch.name] = xy
    placed: dict[str, Placed] = {}
    support: Placed | None = None
    if support_kind is not None:
        if (
            target.catalogue == "Table"
            and support_kind == "table"
            and not sel.hazard_is_target
            and _table_height_ok(target.asset)
        ):
            support = placed.setdefault(target.name, placed_instance(target))
        else:
            support = placed_support(support_kind, instance_name(furniture.CATEGORY[support_kind], used), rng)
        lay.place_on_floor(support, relevant=True, face=True)
        placed[support.name] = support
    side: Placed | None = None
    if sel.hints is not None:  # the LLM's auxiliaries dress the scene instead of random clutter
        clutter = [a for a in sel.hints.auxiliaries if a not in sel.by_catalogue]
    else:
        clutter = clutter_names(sel.kb, set(sel.by_catalogue), rng, settings.build.clutter)
    if clutter:
        side = placed_support("table", instance_name("Table", used), rng)
        spots = [xy for xy in (sel.hints.world_xy(a) for a in clutter) if xy is not None] if sel.hints is not None else []
        if spots:  # the auxiliaries stand where the LLM put them, on a side table outside the cube
            lay.preferred[side.name] = np.mean(spots, axis=0)
        lay.place_on_floor(side, relevant=False, face=True)
        placed[side.name] = side
    task_objects = [target, parent, sel.container, sel.support_var, *sel.aux]

    # Fixed (furniture-sized) objects stand on the floor facing the robot.
    for ch in task_objects:
        if ch is None or ch.name in placed or not ch.fixed or ch is hazard:
            continue
        if ch is parent and _on_a_support(sel):  # a big microwave the hazard is in: onto the counter, below
            continue
        p = placed[ch.name] = placed_instance(ch)
        if ch is sel.support_var and p.front is None and _on_a_support(sel):
            # the counter an appliance stands on: square to the room, its front (the catalogue's -y,
            # where a counter's panels are) towards the robot, so the appliance can face out over it
            p.front = np.array([0.0, -1.0])
        lay.place_on_floor(p, relevant=True, face=True)
    if hazard.fixed and hazard.name not in placed:
        p = placed[hazard.name] = placed_instance(hazard)
        lay.place_on_floor(p, relevant=True, face=True)

    if not sel.hazard_free:
        offer_child_safe_container(sel, lay, placed)

    fix_support = placed.get(sel.support_var.name) if sel.support_var is not None else None
    if hazard.name not in placed:
        if sel.hazard_free:
            # where the fix would leave it: on the fix's own support (the table a hammer is taken down
            # onto), not the high shelf the hazardous version stands it on
            place_hazard_safely(sel, lay, placed, fix_support or support)
        else:
            _place_hazard(sel, lay, placed, support)

    # Remaining loose task objects: on the support (away from its edge) or on the floor; in a
    # hazard-free scene, one that could fire the class itself goes where the made-safe hazard went.
    for ch in task_objects:
        if ch is None or ch.name in placed:
            continue
        p = placed[ch.name] = placed_instance(ch)
        if sel.hazard_free and not ch.fixed and could_fire_the_class(sel, ch.catalogue) \
                and place_like_the_hazard(lay, placed, p, placed[hazard.name], fix_support or support):
            continue
        if support is not None and ch.size < LOOSE_ON_SUPPORT_MAX:
            try:
                lay.place_on_surface(p, support, surface_of(support), inward=INWARD)
                continue
            except ItemFailed:
                pass
        if ch.role in (ObjectRole.CONTAINER, ObjectRole.SUPPORT):
            lay.place_on_floor(p, relevant=True, face=True)  # the arm must reach into it from any side
        else:  # an ordinary object on the open floor would be a tripping hazard the scene never meant
            lay.place_beside(p, room_fixtures(sel.kb, lay))

    # Clutter on the side table, away from its edges; an item that does not fit is left out.
    if side is not None:
        for cat in clutter:
            want = sel.hints.size_for(cat) if sel.hints is not None else None
            asset = asset_choice.pick_asset(cat, role=ObjectRole.CLUTTER, kb=sel.kb, task=sel.task, hc=None, rng=rng,
                                      size=want, real=sel.real_assets)
            ch = asset_choice.Chosen(instance_name(cat, used), cat, ObjectRole.CLUTTER, asset)
            p = placed_instance(ch)
            try:
                lay.place_on_surface(p, side, surface_of(side), inward=INWARD)
            except ItemFailed:
                if sel.hints is not None:
                    sel.hints.note(f"auxiliary:{cat}", "did not fit on the side table; left out")
                continue
            placed[p.name] = p

    items = mix.choose_judgement_items(sel.task.id, sel.task.hazard_class, set(sel.by_catalogue) | set(clutter),
                                       sel.kb, settings, hazard_free=sel.hazard_free, source=sel.task.source)
    place_judgement_items(sel, lay, placed, [s for s in (side, support) if s is not None], items)

    focus = placed[hazard.name]
    holder = placed.get(focus.inside) if focus.inside else None
    try:
        lay.fit_base(focus, holder=holder)
    except ItemFailed:
        if holder is None or holder.support == "floor" or holder.support_geom is not None:
            raise
        _floor_the_holder(lay, holder, focus)  # a deep counter put the appliance out of reach
        lay.fit_base(focus, holder=holder)
    # fit_base proved the hazard reachable from a free base pose; the robot starts at its dock, a
    # pose that does not depend on which object is the hazard, unless the settings ask for the
    # reach pose (the answer key as a start: skill tests and ablations only)
    if settings.build.start == "dock":
        lay.base = lay.dock_pose()
    return lay, placed, support


def _floor_the_holder(lay: Layout, holder: Placed, inside: Placed) -> None:
    """Stand an appliance that sits on a support on the floor instead, with what is inside it: on a
    deep counter the arm cannot reach past the counter's edge into it (welded, it stays put)."""
    lay.items = [p for p in lay.items if p is not holder and p is not inside]
    lay.place_on_floor(holder, relevant=True, face=True)
    lo, hi, cav = cavity_world(holder)
    lay.place_in_cavity(inside, holder, (lo, hi), front=cavity_front(holder, cav))


def _place_hazard(sel: Selection, lay: Layout, placed: dict[str, Placed], support: Placed | None) -> None:
    """The hazard object, where the scenario says: one branch per relation kind of ``schema/placement.py``
    (on the floor, in the walkway, on or at the edge of the scene's support, inside, on or near another
    object); a new kind gets its branch here."""
    where, parent, hazard = sel.placement, sel.parent, sel.hazard
    kind = where.relation
    hp = placed[hazard.name] = placed_instance(hazard)
    if kind == "on" and where.support == "floor":
        lay.place_on_floor(hp, relevant=True, face=reached_from_front(hp))
    elif kind == "walkway":
        fixtures = [p for p in lay.items if p.fixed]
        lay.place_on_floor(hp, relevant=True, face=reached_from_front(hp), clear_of=fixtures)
    elif support is not None:
        edge = kind == "at_edge"
        lay.place_on_surface(
            hp, support, surface_of(support), edge=edge, inward=0.0 if edge else INWARD, near_side=HAZARD_NEAR_SIDE
        )
    elif kind in ("inside", "on", "near") and parent is not None:
        ppl = placed.get(parent.name)
        if ppl is None:
            ppl = placed[parent.name] = placed_instance(parent)
            if kind == "near":
                _stand_on_its_own_surface(sel, lay, placed, ppl)
            else:
                _stand_parent(sel, lay, placed, ppl)
        if kind == "near":
            _place_near(lay, hp, ppl, placed)
        elif kind == "inside":
            lo, hi, cav = cavity_world(ppl)
            lay.place_in_cavity(hp, ppl, (lo, hi), front=cavity_front(ppl, cav))
        else:
            lay.place_on_surface(hp, ppl, surface_of(ppl), inward=0.0)
    else:
        raise ItemFailed(f"unsupported placement '{sel.placement}'")


def _place_near(lay: Layout, hp: Placed, ppl: Placed, placed: dict[str, Placed]) -> None:
    """The hazard right beside the object the scenario names: on the floor against it when it stands
    on the floor, else on the same surface a few centimetres from it (a spray bottle by the bread)."""
    if ppl.support == "floor":
        was = ppl.fixed
        ppl.fixed = True  # place_beside tucks things against fixed bodies only
        try:
            lay.place_beside(hp, [ppl])
        finally:
            ppl.fixed = was
        if _h_gap(hp, ppl) <= NEAR_GAP[1] + 0.05:
            return
        lay.items.remove(hp)
        raise ItemFailed(f"no room on the floor beside {ppl.name} for {hp.name}")
    holder = placed.get(str(ppl.support).split(":", 1)[0])
    if holder is None:
        raise ItemFailed(f"{ppl.name} stands on nothing {hp.name} could share")
    for _ in range(FACING_TRIES):
        lay.place_on_surface(hp, holder, surface_of(holder), inward=0.02)
        if _h_gap(hp, ppl) <= NEAR_GAP[1]:
            return
        lay.items.remove(hp)
    raise ItemFailed(f"found no spot on {holder.name} within {NEAR_GAP[1]:.2f} m of {ppl.name} for {hp.name}")


def _stand_on_its_own_surface(sel: Selection, lay: Layout, placed: dict[str, Placed], ppl: Placed) -> None:
    """A small thing another object stands near (a loaf of bread) goes where it usually rests: on a
    table or counter of its own when the knowledge base says it is not kept on the floor."""
    info = sel.kb.objects.get(ppl.catalogue)
    kinds = [k for k in (info.supports if info else []) if k in furniture.CATEGORY]
    if info is None or "floor" in info.supports or not kinds:
        lay.place_on_floor(ppl, relevant=True, face=True)
        return
    surface = placed_support(kinds[0], instance_name(furniture.CATEGORY[kinds[0]], sel.used), sel.rng)
    lay.place_on_floor(surface, relevant=True, face=True)
    placed[surface.name] = surface
    lay.place_on_surface(ppl, surface, surface_of(surface), inward=INWARD, near_side=HAZARD_NEAR_SIDE)


def _h_gap(a: Placed, b: Placed) -> float:
    """Horizontal gap between two placed boxes (0 when they overlap)."""
    ac, ah, bc, bh = a.world_center(), a.world_half(), b.world_center(), b.world_half()
    return float(np.linalg.norm(np.maximum(0.0, np.abs(ac[:2] - bc[:2]) - ah[:2] - bh[:2])))


def _on_a_support(sel: Selection) -> bool:
    """Does the object the hazard is in or on stand on the scene's support rather than the floor?
    (the knowledge base says it never stands on the floor, and the support is of a kind it stands on)"""
    if sel.parent is None or sel.support_var is None:
        return False
    info = sel.kb.objects.get(sel.parent.catalogue)
    kind = next((k for k, c in furniture.CATEGORY.items() if c == sel.support_var.catalogue), None)
    return info is not None and "floor" not in info.supports and kind in info.supports


def _stand_parent(sel: Selection, lay: Layout, placed: dict[str, Placed], ppl: Placed) -> None:
    """The object the hazard is in or on: on the scene's support when the knowledge base says it
    stands on that kind of surface and not on the floor (a microwave sits on the counter), else on
    the floor facing the robot. On a support it is welded there: the asset's hollow shell weighs a
    fraction of a real microwave on its rubber feet, and a door pull dragged it across the counter."""
    holder = placed.get(sel.support_var.name) if sel.support_var is not None else None
    if holder is not None and _on_a_support(sel):
        ppl.fixed = True
        if ppl.front is not None and _at_front_edge(lay, ppl, holder):
            return
        for _ in range(FACING_TRIES):  # the surface draws a random yaw: keep one whose door faces the robot
            lay.place_on_surface(ppl, holder, surface_of(holder), inward=INWARD)
            if ppl.front is None:
                return
            c, s_ = np.cos(ppl.yaw), np.sin(ppl.yaw)
            front = np.array([c * ppl.front[0] - s_ * ppl.front[1], s_ * ppl.front[0] + c * ppl.front[1]])
            to_base = lay.base[:2] - ppl.pos[:2]
            if float(np.dot(front, to_base)) > 0.6 * float(np.linalg.norm(to_base)):
                return
            lay.items.remove(ppl)
        raise ItemFailed(f"{ppl.name} found no spot on {holder.name} with its door towards the room")
    lay.place_on_floor(ppl, relevant=True, face=True)


def _at_front_edge(lay: Layout, ppl: Placed, holder: Placed) -> bool:
    """Stand an appliance near the edge of its support that faces the robot (the open floor), its
    door facing out over that edge, as a microwave stands on a kitchen counter. Drawn anywhere on the
    top with its door towards the robot, it stood up to 0.64 m in from the edge, its door along the
    worktop, where the arm reaching over the counter could not get into it. False when it does not fit."""
    surface = surface_of(holder)
    axis, sign = lay.robot_edge(surface)
    out = np.zeros(2)
    out[axis] = sign
    yaw = face_robot_yaw(ppl.front, out)
    try:
        lay.place_on_surface(ppl, holder, surface, edge=True, inward=INWARD, yaw=yaw)
    except ItemFailed:
        return False
    return True


def _table_height_ok(asset) -> bool:
    """A catalogue Table may serve as the 'table' support only at a table's height (KB range)."""
    lo, hi = furniture._heights().get("table", furniture.DEFAULT_HEIGHTS["table"])
    tops = [s.center[2] for s in asset.surfaces] or [float(asset.aabb[1][2])]
    return lo - 0.02 <= max(tops) <= hi + 0.02
