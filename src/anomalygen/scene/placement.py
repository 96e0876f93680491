"""Where every chosen object stands: supports, furniture, the hazard, loose task objects, clutter.

``place`` lays out a ``selection.Selection`` with ``layout.Layout`` (the hazard where its scenario says,
or safely for a hazard-free scene) and moves the robot base within reach of the hazard.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from anomalygen.errors import ItemFailed
from anomalygen.scene import furniture, mix, select
from anomalygen.scene.instances import (
    HAZARD_NEAR_SIDE,
    INWARD,
    cavity_world,
    instance_name,
    placed_instance,
    placed_support,
    surface_of,
)
from anomalygen.scene.judgement import place_hazard_safely, place_judgement_items, room_fixtures
from anomalygen.scene.layout import Layout, Placed
from anomalygen.scene.selection import Selection, clutter_names
from anomalygen.schema import ObjectRole

if TYPE_CHECKING:
    from anomalygen.config import Settings


SURFACE_PLACEMENTS = {"table", "low_table", "table_edge", "counter", "counter_edge", "shelf"}
LOOSE_ON_SUPPORT_MAX = 0.35  # m: a loose task object smaller than this goes on the support, not the floor


def place(sel: Selection, settings: Settings) -> tuple[Layout, dict[str, Placed], Placed | None]:
    """Place every chosen object (and the clutter) in the room; returns the layout, the placed
    objects by name and the support the hazard stands on (if any)."""
    rng, kind, used = sel.rng, sel.kind, sel.used
    target, parent, hazard = sel.target, sel.parent, sel.hazard
    support_kind = kind if kind in SURFACE_PLACEMENTS else None
    lay = Layout(rng, relevant_in_cube=settings.build.relevant_in_unit_cube)
    if sel.hints is not None:
        for ch in sel.by_catalogue.values():
            xy = sel.hints.world_xy(ch.catalogue)
            if xy is not None:
                lay.preferred[ch.name] = xy
    placed: dict[str, Placed] = {}
    support: Placed | None = None
    if support_kind is not None:
        base_kind = support_kind.replace("_edge", "")
        if (
            target.catalogue == "Table"
            and base_kind == "table"
            and not sel.hazard_is_target
            and _table_height_ok(target.asset)
        ):
            support = placed.setdefault(target.name, placed_instance(target))
        else:
            support = placed_support(base_kind, instance_name(furniture.CATEGORY[base_kind], used), rng)
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
        p = placed[ch.name] = placed_instance(ch)
        lay.place_on_floor(p, relevant=True, face=True)
    if hazard.fixed and hazard.name not in placed:
        p = placed[hazard.name] = placed_instance(hazard)
        lay.place_on_floor(p, relevant=True, face=True)

    if hazard.name not in placed:
        if sel.hazard_free:
            place_hazard_safely(sel, lay, placed, support)
        else:
            _place_hazard(sel, lay, placed, support, support_kind)

    # Remaining loose task objects: on the support (away from its edge) or on the floor.
    for ch in task_objects:
        if ch is None or ch.name in placed:
            continue
        p = placed[ch.name] = placed_instance(ch)
        if support is not None and ch.size < LOOSE_ON_SUPPORT_MAX:
            try:
                lay.place_on_surface(p, support, surface_of(support), inward=INWARD)
                continue
            except ItemFailed:
                pass
        lay.place_beside(p, room_fixtures(sel.kb, lay))

    # Clutter on the side table, away from its edges; an item that does not fit is left out.
    if side is not None:
        for cat in clutter:
            want = sel.hints.size_for(cat) if sel.hints is not None else None
            asset = select.pick_asset(cat, role=ObjectRole.CLUTTER, kb=sel.kb, task=sel.task, hc=None, rng=rng,
                                      size=want)
            ch = select.Chosen(instance_name(cat, used), cat, ObjectRole.CLUTTER, asset)
            p = placed_instance(ch)
            try:
                lay.place_on_surface(p, side, surface_of(side), inward=INWARD)
            except ItemFailed:
                if sel.hints is not None:
                    sel.hints.note(f"auxiliary:{cat}", "did not fit on the side table; left out")
                continue
            placed[p.name] = p

    items = mix.choose_judgement_items(sel.task.id, sel.task.hazard_class, set(sel.by_catalogue) | set(clutter),
                                       sel.kb, settings, hazard_free=sel.hazard_free)
    place_judgement_items(sel, lay, placed, [s for s in (side, support) if s is not None], items)

    focus = placed[hazard.name]
    lay.fit_base(focus, holder=placed.get(focus.inside) if focus.inside else None)
    return lay, placed, support


def _place_hazard(sel: Selection, lay: Layout, placed: dict[str, Placed], support: Placed | None,
                  support_kind: str | None) -> None:
    """The hazard object, where the scenario says."""
    kind, parent, hazard = sel.kind, sel.parent, sel.hazard
    hp = placed[hazard.name] = placed_instance(hazard)
    if kind == "floor":
        lay.place_on_floor(hp, relevant=True, face=False)
    elif kind == "walkway":
        fixtures = [p for p in lay.items if p.fixed]
        lay.place_on_floor(hp, relevant=True, face=False, clear_of=fixtures)
    elif support is not None:
        edge = support_kind.endswith("_edge")
        lay.place_on_surface(
            hp, support, surface_of(support), edge=edge, inward=0.0 if edge else INWARD, near_side=HAZARD_NEAR_SIDE
        )
    elif kind in ("inside", "on") and parent is not None:
        ppl = placed.get(parent.name)
        if ppl is None:
            ppl = placed[parent.name] = placed_instance(parent)
            lay.place_on_floor(ppl, relevant=True, face=True)
        if kind == "inside":
            lo, hi, _ = cavity_world(ppl)
            lay.place_in_cavity(hp, ppl, (lo, hi))
        else:
            lay.place_on_surface(hp, ppl, surface_of(ppl), inward=0.0)
    else:
        raise ItemFailed(f"unsupported placement {sel.task.scenario.placement!r}")


def _table_height_ok(asset) -> bool:
    """A catalogue Table may serve as the 'table' support only at a table's height (KB range)."""
    lo, hi = furniture._heights().get("table", furniture.DEFAULT_HEIGHTS["table"])
    tops = [s.center[2] for s in asset.surfaces] or [float(asset.aabb[1][2])]
    return lo - 0.02 <= max(tops) <= hi + 0.02
