"""From a TaskProposal to a physically valid MuJoCo scene in which the hazard really exists.

Pipeline of one attempt (all randomness from ``item_rng(seed, task.id, attempt)``):

1. select assets (select.py): hazard, target, the object the hazard sits in/on, the container of the
   fix, task co-objects, unrelated clutter; sizes from the knowledge base, clamped by spatial rules;
   initial joint states that make the hazard real;
2. place them (layout.py) and move the robot base within reach;
3. compose one MjSpec (robot + room + objects), compile, reject initial interpenetration;
4. settle the physics for ``settings.build.settle_s``;
5. validate (validate.py): interpenetration <= 1 mm, velocities settled, and the hazard class's
   preconditions hold on the scene graph of the settled state.

A failed attempt is repaired by re-sampling (``settings.build.repair_attempts`` times); then the item
fails with the last one-line reason. Outputs are written only for a valid scene.
"""

from __future__ import annotations

import logging
import math
import os
import shutil
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from anomalygen.errors import ItemFailed
from anomalygen.rng import item_rng, stable_hash
from anomalygen.runfolder import atomic_write_bytes, atomic_write_text, write_model
from anomalygen.scene import furniture, layout, mix, robot, robot_model, select
from anomalygen.scene.graph import FLOOR_GEOM
from anomalygen.scene.layout import Layout, Placed
from anomalygen.scene.sensors import add_observation_sensors
from anomalygen.schema import (
    CLOSURE_LABELS,
    ENCLOSING_LABELS,
    SWINGING_CLOSURES,
    AssetRef,
    AssetSource,
    JointState,
    ObjectRole,
    PlacedObject,
    SceneSpec,
    TaskProposal,
    ValidationCheck,
    ValidationReport,
)

if TYPE_CHECKING:
    from anomalygen.config import Settings

log = logging.getLogger(__name__)
SURFACE_PLACEMENTS = {"table", "low_table", "table_edge", "counter", "counter_edge", "shelf"}
CAMERAS = ("front", "top", "wrist")
MAX_AUX = 3
CONTAINER_REDRAWS = 4  # other container sizes drawn before a smaller hazard is tried
INWARD = 0.13  # m kept from a support's edge by things that are not the edge hazard
HAZARD_NEAR_SIDE = 0.4  # m: the hazard's centre at most this far from the robot-facing edge (arm's reach)
FACING_TRIES = 16  # draws of a parent's spot on its support until its door faces the robot
LOOSE_ON_SUPPORT_MAX = 0.35  # m: a loose task object smaller than this goes on the support, not the floor
CLUTTER_MAX_SIZE = 0.3
SAFE_STATE = {"open": "closed", "on": "off"}  # a part's state in a hazard-free scene


LOOSE_SOLREF = 0.005  # s: contact time constant of loose objects (2.5 physics steps)


@lru_cache(maxsize=1)
def _kb():
    from anomalygen.knowledge import load_kb

    return load_kb()


@dataclass
class Built:
    """A compiled, settled scene in memory (what the outputs are written from)."""

    spec: SceneSpec
    mjspec: object
    model: object
    data: object
    report: ValidationReport
    graph: object


# ============================================================================ selection


def _instance_name(catalogue: str, used: set[str]) -> str:
    base = catalogue.lower()
    i = 0
    while f"{base}_{i}" in used:
        i += 1
    name = f"{base}_{i}"
    used.add(name)
    return name


def _parse_placement(placement: str) -> tuple[str, str | None]:
    for prefix in ("inside:", "on:"):
        if placement.startswith(prefix):
            return prefix[:-1], placement[len(prefix) :]
    return placement, None


def _front(asset) -> np.ndarray | None:
    """Local direction the asset's doors/drawers open to (the catalogue convention is -y)."""
    if any(j.label in CLOSURE_LABELS for j in asset.joints) or asset.cavities:
        return np.array([0.0, -1.0])
    return None


def _sweep(asset, values: dict[str, float]) -> float:
    """How far open doors/drawers reach out of the closed bounding box, conservatively."""
    ext = asset.aabb[1] - asset.aabb[0]
    out = 0.0
    for j in asset.joints:
        v = values.get(j.name)
        if v is None or abs(v - j.closed_value) < 1e-6:
            continue
        if j.type == "slide":
            out = max(out, abs(v - j.closed_value) + 0.02)
        elif j.label in SWINGING_CLOSURES:
            out = max(out, min(float(max(ext[0], ext[2] if abs(j.axis[2]) < 0.5 else ext[0])), 1.0))
    return out


def _placed(chosen: select.Chosen) -> Placed:
    lo, hi = (np.asarray(v, float) for v in chosen.asset.aabb)
    p = Placed(
        name=chosen.name,
        catalogue=chosen.catalogue,
        role=chosen.role,
        lo=lo,
        hi=hi,
        fixed=chosen.fixed,
        asset=chosen.asset,
        joint_values=dict(chosen.joint_values),
        front=_front(chosen.asset),
    )
    p.sweep = _sweep(chosen.asset, chosen.joint_values)
    return p


def _support_placed(kind: str, name: str, rng, role=ObjectRole.SUPPORT) -> Placed:
    sup = furniture.sample_support(kind, rng)
    lo, hi = sup.aabb()
    return Placed(
        name=name,
        catalogue=sup.category,
        role=role,
        lo=lo,
        hi=hi,
        fixed=True,
        support_geom=sup,
        front=np.array([-1.0, 0.0]),
    )


def _surface_of(holder: Placed):
    """The top surface of a holder in world coordinates: (lo_xy, hi_xy, top_z)."""
    if holder.support_geom is not None:
        s = holder.support_geom
        return layout.surface_world(holder, (0.0, 0.0, s.top), s.half)
    surfaces = list(holder.asset.surfaces)
    if not surfaces:
        lo, hi = holder.asset.aabb
        return layout.surface_world(
            holder, (0.0, 0.0, float(hi[2])), (float(hi[0] - lo[0]) / 2 * 0.8, float(hi[1] - lo[1]) / 2 * 0.8)
        )
    best = max(surfaces, key=lambda s: s.half_size[0] * s.half_size[1])
    return layout.surface_world(holder, best.center, best.half_size)


def _cavity_world(holder: Placed):
    asset = holder.asset
    if not asset.cavities:
        raise ItemFailed(f"{holder.catalogue} has no interior to put things in")
    cav = max(asset.cavities, key=lambda c: float(np.prod(c.half_extents)))
    center = np.asarray(cav.center, float).copy()
    if cav.joint is not None:
        j = asset.joint(cav.joint)
        if j.type == "slide":
            v = holder.joint_values.get(j.name, j.closed_value)
            center += np.asarray(j.axis) * (v - 0.0)
    c, s = math.cos(holder.yaw), math.sin(holder.yaw)
    wc = holder.pos + np.array([c * center[0] - s * center[1], s * center[0] + c * center[1], center[2]])
    h = np.asarray(cav.half_extents, float)
    wh = np.array([abs(c) * h[0] + abs(s) * h[1], abs(s) * h[0] + abs(c) * h[1], h[2]])
    return wc - wh, wc + wh, cav


def _container_room(asset) -> float:
    """Longest thing that lies flat in the container's biggest cavity (along its long side)."""
    cav = max(asset.cavities, key=lambda c: float(np.prod(c.half_extents)))
    return 0.95 * 2 * float(max(cav.half_extents[0], cav.half_extents[1]))


def _cavity_cap(asset) -> float:
    cav = max(asset.cavities, key=lambda c: float(np.prod(c.half_extents)))
    return 0.8 * 2 * float(min(cav.half_extents))


def is_dressing(kb, name: str) -> bool:
    """Can ``name`` dress a scene as clutter? Small household things with no hazard property, so a
    decoration never becomes a second hazard (also the filter for the LLM engine's auxiliaries)."""
    from anomalygen.knowledge.models import HAZARD_PROPERTIES

    info = kb.objects.get(name)
    if info is None or info.kind != "household":
        return False
    if set(info.properties) & (HAZARD_PROPERTIES | {"furniture", "appliance"}):
        return False
    return info.size_range[0] <= CLUTTER_MAX_SIZE


def _clutter_names(kb, exclude: set[str], rng, n: int) -> list[str]:
    names = [name for name in select._catalogue() if name not in exclude and is_dressing(kb, name)]
    if not names or n <= 0:
        return []
    idx = rng.choice(len(names), size=min(n, len(names)), replace=False)
    return [names[i] for i in sorted(idx)]


@dataclass
class Selection:
    """The objects chosen for one task, by role, before anything is placed (``select_objects``)."""

    task: TaskProposal
    rng: np.random.Generator
    kb: object
    hc: object  # the task's HazardClass, or None
    kind: str  # placement kind: floor, walkway, a surface, inside, on
    parent_raw: str | None
    used: set[str] = field(default_factory=set)
    by_catalogue: dict[str, select.Chosen] = field(default_factory=dict)
    target: select.Chosen | None = None
    parent: select.Chosen | None = None
    hazard: select.Chosen | None = None
    hazard_var: select.Chosen | None = None  # the object bound to $hazard
    container: select.Chosen | None = None
    support_var: select.Chosen | None = None
    aux: list[select.Chosen] = field(default_factory=list)
    hazard_is_target: bool = False
    hints: object | None = None  # scene/hints.py: sizes, positions and auxiliaries from the LLM engine
    hazard_free: bool = False  # build the task's hazard in its safe state (scene/mix.py)

    @property
    def variables(self) -> set[str]:
        return set(self.hc.variables) if self.hc is not None else set()

    def choose(self, raw: str, role: ObjectRole, *, cap=None, rank=False) -> select.Chosen:
        """The asset for a name (one per catalogue category: a second mention reuses it)."""
        cat = select.resolve_name(raw)
        if cat in self.by_catalogue:
            return self.by_catalogue[cat]
        want = self.hints.size_for(cat) if self.hints is not None else None
        asset = select.pick_asset(cat, role=role, kb=self.kb, task=self.task, hc=self.hc, rng=self.rng, cap=cap,
                                  rank=rank, size=want)
        if want is not None and abs(asset.size - want) > 1e-3:
            self.hints.note(f"size:{cat}", f"size {want:.3f} m does not fit the generator's range or the space "
                            f"available; built at {asset.size:.3f} m", value=want, limit=round(float(asset.size), 4))
        ch = select.Chosen(_instance_name(cat, self.used), cat, role, asset)
        self.by_catalogue[cat] = ch
        return ch

    def forget(self, ch: select.Chosen) -> None:
        """Drop a choice so the next ``choose`` of its category draws again."""
        self.by_catalogue.pop(ch.catalogue, None)
        self.used.discard(ch.name)


def select_objects(task: TaskProposal, rng, hints=None) -> Selection:
    """Choose an asset for every role the task needs (target, hazard, container, supports, co-objects).

    ``hints`` (scene/hints.py, from the LLM engine) supply sizes, floor positions and the auxiliary
    objects instead of the random draws; every correction is noted in them or in the layout."""
    kb = _kb()
    sc = task.scenario
    kind, parent_raw = _parse_placement(sc.placement)
    sel = Selection(task, rng, kb, kb.hazard_classes.get(task.hazard_class), kind, parent_raw, hints=hints)
    hc, variables = sel.hc, sel.variables
    sel.hazard_is_target = select.resolve_name(sc.hazard_object) == select.resolve_name(task.target_asset)
    # Big things first: they bound what fits in/on them.
    target = sel.target = sel.choose(
        task.target_asset, ObjectRole.HAZARD if sel.hazard_is_target else ObjectRole.TARGET, rank=True
    )
    parent = sel.parent = sel.choose(parent_raw, ObjectRole.AUXILIARY) if parent_raw else None
    cap = None
    if kind == "inside" and parent is not None:
        if not parent.asset.cavities:
            raise ItemFailed(f"placement inside:{parent_raw} but {parent.catalogue} has no interior")
        cap = _cavity_cap(parent.asset)
    hazard = sel.choose(sc.hazard_object, ObjectRole.HAZARD, cap=cap)
    if hazard is target:
        target.role = ObjectRole.HAZARD

    container = None
    container_name = sc.container or (
        _first_known(hc.default_containers) if "$container" in variables else None
    )
    if container_name:
        container = sel.choose(container_name, ObjectRole.CONTAINER)
        if container is not hazard and container.asset.cavities:
            # The hazard must be able to go in: a 0.5 m plastic bag does not fit a 0.3 m bucket.
            # Draw the container again (other sizes), then a smaller hazard, before giving up.
            # A container that is also the scene's target keeps its draw (other steps refer to it).
            for _ in range(CONTAINER_REDRAWS if container is not target else 0):
                if hazard.size <= _container_room(container.asset):
                    break
                sel.forget(container)
                container = sel.choose(container_name, ObjectRole.CONTAINER)
            room = _container_room(container.asset)
            if hazard.size > room and hazard is not target:
                sel.forget(hazard)
                hazard = sel.choose(sc.hazard_object, ObjectRole.HAZARD, cap=min(cap or room, room))
            if hazard.size > room:
                raise ItemFailed(f"{hazard.catalogue} ({hazard.size:.2f} m) does not fit {container.catalogue} "
                                 f"(room for {room:.2f} m)")
    sel.hazard, sel.container = hazard, container
    if "$support" in variables:
        sname = _first_known(hc.default_supports)
        if sname:
            sel.support_var = sel.choose(sname, ObjectRole.SUPPORT)

    extra = list(sc.co_objects) + [a.name for a in task.auxiliary_items if a.relevant]
    for raw in extra:
        if len(sel.aux) >= MAX_AUX:
            break
        try:
            cat = select.resolve_name(raw)
        except ItemFailed:
            continue  # an unknown co-object is decoration, not the hazard: leave it out
        if cat in sel.by_catalogue:
            continue
        sel.aux.append(sel.choose(cat, ObjectRole.AUXILIARY))
    bind_hazard(sel)
    return sel


def bind_hazard(sel: Selection) -> None:
    """Which object plays $hazard. Classes with both $target and $hazard (a closed window and a hot
    source) whose scenario names the target as its hazard object: the co-object with the class's
    properties."""
    sel.hazard_var = sel.hazard
    hc, target = sel.hc, sel.target
    if hc is not None and sel.hazard is target and {"$hazard", "$target"} <= sel.variables:
        sel.hazard_var = _co_object_for(hc, sel.kb, sel.aux)
        if sel.hazard_var is None:
            raise ItemFailed(f"no co-object can play $hazard for a {hc.id} scene")
        sel.hazard_var.role = ObjectRole.HAZARD
        target.role = ObjectRole.TARGET


def set_initial_joints(sel: Selection) -> None:
    """Initial joint states: the task's articulations and the class template (and an interior the
    hazard sits in is opened unless the task says it is closed)."""
    task, hc, parent = sel.task, sel.hc, sel.parent
    uses: dict[str, list[tuple[str, str]]] = {}
    for a in task.articulations:
        try:
            uses.setdefault(select.resolve_name(a.object), []).append((a.part, a.initial_state))
        except ItemFailed:
            continue
    if hc is not None and hc.articulation is not None:
        var_obj = {"$target": sel.target, "$hazard": sel.hazard}.get(hc.articulation.variable)
        if var_obj is not None:
            uses.setdefault(var_obj.catalogue, []).append(
                (hc.articulation.part, hc.articulation.initial_state)
            )
    if sel.kind == "inside" and parent is not None:
        cav = max(parent.asset.cavities, key=lambda c: float(np.prod(c.half_extents)))
        if cav.joint is not None and not any(
            p in ENCLOSING_LABELS and s == "closed" for p, s in uses.get(parent.catalogue, [])
        ):
            label = parent.asset.joint(cav.joint).label
            uses.setdefault(parent.catalogue, []).append((label, "open"))
    if sel.hazard_free:  # every part the hazard needed open or on is built shut instead
        uses = {cat: [(p, SAFE_STATE.get(st, st)) for p, st in pairs] for cat, pairs in uses.items()}
    for cat, pairs in uses.items():
        if cat in sel.by_catalogue:
            select.set_articulations(sel.by_catalogue[cat], pairs, sel.rng)
    if not sel.hazard_free:
        _check_articulations(task, hc, sel.by_catalogue, sel.target)


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
            support = placed.setdefault(target.name, _placed(target))
        else:
            support = _support_placed(base_kind, _instance_name(furniture.CATEGORY[base_kind], used), rng)
        lay.place_on_floor(support, relevant=True, face=True)
        placed[support.name] = support
    side: Placed | None = None
    if sel.hints is not None:  # the LLM's auxiliaries dress the scene instead of random clutter
        clutter = [a for a in sel.hints.auxiliaries if a not in sel.by_catalogue]
    else:
        clutter = _clutter_names(sel.kb, set(sel.by_catalogue), rng, settings.build.clutter)
    if clutter:
        side = _support_placed("table", _instance_name("Table", used), rng)
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
        p = placed[ch.name] = _placed(ch)
        lay.place_on_floor(p, relevant=True, face=True)
    if hazard.fixed and hazard.name not in placed:
        p = placed[hazard.name] = _placed(hazard)
        lay.place_on_floor(p, relevant=True, face=True)

    if hazard.name not in placed:
        if sel.hazard_free:
            _place_hazard_safely(sel, lay, placed, support)
        else:
            _place_hazard(sel, lay, placed, support, support_kind)

    # Remaining loose task objects: on the support (away from its edge) or on the floor.
    for ch in task_objects:
        if ch is None or ch.name in placed:
            continue
        p = placed[ch.name] = _placed(ch)
        if support is not None and ch.size < LOOSE_ON_SUPPORT_MAX:
            try:
                lay.place_on_surface(p, support, _surface_of(support), inward=INWARD)
                continue
            except ItemFailed:
                pass
        lay.place_on_floor(p, relevant=True, face=True)

    # Clutter on the side table, away from its edges; an item that does not fit is left out.
    if side is not None:
        for cat in clutter:
            want = sel.hints.size_for(cat) if sel.hints is not None else None
            asset = select.pick_asset(cat, role=ObjectRole.CLUTTER, kb=sel.kb, task=sel.task, hc=None, rng=rng,
                                      size=want)
            ch = select.Chosen(_instance_name(cat, used), cat, ObjectRole.CLUTTER, asset)
            p = _placed(ch)
            try:
                lay.place_on_surface(p, side, _surface_of(side), inward=INWARD)
            except ItemFailed:
                if sel.hints is not None:
                    sel.hints.note(f"auxiliary:{cat}", "did not fit on the side table; left out")
                continue
            placed[p.name] = p

    items = mix.choose_judgement_items(sel.task.id, sel.task.hazard_class, set(sel.by_catalogue) | set(clutter),
                                       sel.kb, settings, hazard_free=sel.hazard_free)
    _place_judgement_items(sel, lay, placed, [s for s in (side, support) if s is not None], items)

    focus = placed[hazard.name]
    lay.fit_base(focus, holder=placed.get(focus.inside) if focus.inside else None)
    return lay, placed, support


def _place_judgement_items(sel: Selection, lay: Layout, placed: dict[str, Placed], surfaces: list[Placed],
                           items: mix.JudgementItems) -> None:
    """Near-misses well inside a table top (any that find no room are left out); the second hazard
    on the floor, with its bin when the scene has none."""
    rng = items.rng
    for cat in items.near_misses if surfaces else []:
        asset = select.pick_asset(cat, role=ObjectRole.CLUTTER, kb=sel.kb, task=sel.task, hc=None, rng=rng)
        p = _placed(select.Chosen(_instance_name(cat, sel.used), cat, ObjectRole.CLUTTER, asset))
        holder = surfaces[int(rng.integers(len(surfaces)))]
        try:
            lay.place_on_surface(p, holder, _surface_of(holder), inward=INWARD)
        except ItemFailed:
            continue
        placed[p.name] = p
    for cat, role, face in ((items.second_hazard, ObjectRole.HAZARD, False), (items.bin, ObjectRole.CONTAINER, True)):
        if cat is None:
            continue
        asset = select.pick_asset(cat, role=role, kb=sel.kb, task=sel.task, hc=None, rng=rng)
        p = _placed(select.Chosen(_instance_name(cat, sel.used), cat, role, asset))
        lay.place_on_floor(p, relevant=True, face=face)
        placed[p.name] = p


def _place_hazard(sel: Selection, lay: Layout, placed: dict[str, Placed], support: Placed | None,
                  support_kind: str | None) -> None:
    """The hazard object, where the scenario says."""
    kind, parent, hazard = sel.kind, sel.parent, sel.hazard
    hp = placed[hazard.name] = _placed(hazard)
    if kind == "floor":
        lay.place_on_floor(hp, relevant=True, face=False)
    elif kind == "walkway":
        fixtures = [p for p in lay.items if p.fixed]
        lay.place_on_floor(hp, relevant=True, face=False, clear_of=fixtures)
    elif support is not None:
        edge = support_kind.endswith("_edge")
        lay.place_on_surface(
            hp, support, _surface_of(support), edge=edge, inward=0.0 if edge else INWARD, near_side=HAZARD_NEAR_SIDE
        )
    elif kind in ("inside", "on") and parent is not None:
        ppl = placed.get(parent.name)
        if ppl is None:
            ppl = placed[parent.name] = _placed(parent)
            _stand_parent(sel, lay, placed, ppl)
        if kind == "inside":
            lo, hi, _ = _cavity_world(ppl)
            lay.place_in_cavity(hp, ppl, (lo, hi))
        else:
            lay.place_on_surface(hp, ppl, _surface_of(ppl), inward=0.0)
    else:
        raise ItemFailed(f"unsupported placement {sel.task.scenario.placement!r}")


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
        for _ in range(FACING_TRIES):  # the surface draws a random yaw: keep one whose door faces the robot
            lay.place_on_surface(ppl, holder, _surface_of(holder), inward=INWARD)
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


def _place_hazard_safely(sel: Selection, lay: Layout, placed: dict[str, Placed], support: Placed | None) -> None:
    """The task's object where it is no hazard: shut inside its container, else well inside the
    surface, else on the floor away from the walkway (a second chance for the layout)."""
    hazard, container = sel.hazard, sel.container
    hp = placed[hazard.name] = _placed(hazard)
    if container is not None and container is not hazard and container.asset.cavities:
        holder = placed.get(container.name)
        if holder is None:
            holder = placed[container.name] = _placed(container)
            lay.place_on_floor(holder, relevant=True, face=True)
        lo, hi, _ = _cavity_world(holder)
        lay.place_in_cavity(hp, holder, (lo, hi))
        for joint in container.asset.joints:  # shut every lid, door and drawer of the container
            if select.kb_label(joint.label) in ENCLOSING_LABELS:
                holder.joint_values[joint.name] = float(joint.closed_value)
        holder.sweep = 0.0
        return
    if support is not None:
        lay.place_on_surface(hp, support, _surface_of(support), inward=INWARD, near_side=HAZARD_NEAR_SIDE)
        return
    fixtures = [p for p in lay.items if p.fixed]
    lay.place_on_floor(hp, relevant=True, face=False, clear_of=fixtures)


def bind_roles(sel: Selection, support: Placed | None) -> dict[str, str]:
    """The role variables ($hazard, $target, $container, $support) bound to instance names."""
    kind, parent = sel.kind, sel.parent
    bindings = {"$hazard": sel.hazard_var.name, "$target": sel.target.name}
    if sel.container is not None:
        bindings["$container"] = sel.container.name
    if sel.support_var is not None:
        bindings["$support"] = sel.support_var.name
    elif support is not None:
        bindings["$support"] = support.name
    elif kind == "on" and parent is not None:
        bindings["$support"] = parent.name
    if kind == "inside" and parent is not None and sel.container is None:
        bindings["$container"] = parent.name
    return bindings


def _plan(task: TaskProposal, settings: Settings, rng, hints=None,
          hazard_free: bool = False) -> tuple[Layout, dict[str, str], dict[str, Placed]]:
    """Choose and place every object; returns the layout, bindings and instances by name.

    A hazard-free scene has no bindings: there is nothing to fix, and the oracle plans nothing."""
    sel = select_objects(task, rng, hints)
    sel.hazard_free = hazard_free
    set_initial_joints(sel)
    lay, placed, support = place(sel, settings)
    return lay, ({} if hazard_free else bind_roles(sel, support)), placed


def _co_object_for(hc, kb, candidates) -> select.Chosen | None:
    """The first candidate whose KB properties satisfy every has_property precondition on $hazard."""
    calls = [c for c in hc.preconditions if c.name == "has_property" and c.args.get("object") == "$hazard"]
    for ch in candidates:
        info = kb.objects.get(ch.catalogue)
        props = set(info.properties) if info is not None else set()
        ok = True
        for c in calls:
            has = bool(props & {p.strip() for p in str(c.args.get("property", "")).split("|")})
            ok &= has != c.negate
        if ok:
            return ch
    return None


def _table_height_ok(asset) -> bool:
    """A catalogue Table may serve as the 'table' support only at a table's height (KB range)."""
    lo, hi = furniture._heights().get("table", furniture.DEFAULT_HEIGHTS["table"])
    tops = [s.center[2] for s in asset.surfaces] or [float(asset.aabb[1][2])]
    return lo - 0.02 <= max(tops) <= hi + 0.02


def _first_known(names: list[str]) -> str | None:
    for n in names:
        try:
            return select.resolve_name(n)
        except ItemFailed:
            continue
    return None


def _check_articulations(task, hc, by_catalogue, target) -> None:
    """The joint the hazard class is about must exist on its object (else the hazard cannot be real)."""
    if hc is None or hc.articulation is None:
        return
    ch = target if hc.articulation.variable == "$target" else None
    if ch is None:
        return
    part = hc.articulation.part
    if not select.joints_with_label(ch.asset, part):
        raise ItemFailed(f"{ch.catalogue} has no '{part}' joint for a {hc.id} scene")


# ============================================================================ composition


def _look_at_xyaxes(eye, target) -> list[float]:
    """Camera xyaxes (MuJoCo cameras look along -z) for a camera at ``eye`` looking at ``target``."""
    fwd = np.asarray(target, float) - np.asarray(eye, float)
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, [0.0, 0.0, 1.0])
    if np.linalg.norm(right) < 1e-6:
        right = np.array([0.0, -1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    return [*right.tolist(), *up.tolist()]


def _compose(lay: Layout, placed: dict[str, Placed], settings: Settings, rng):
    import mujoco

    spec = robot_model.build_robot_spec(tuple(lay.base))
    spec.modelname = "anomalygen_scene"
    spec.option.timestep = 0.002
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.visual.global_.offwidth = max(640, settings.build.render_width)
    spec.visual.global_.offheight = max(480, settings.build.render_height)
    spec.visual.quality.shadowsize = 512
    tex = spec.add_texture(
        name="floor_tex",
        type=mujoco.mjtTexture.mjTEXTURE_2D,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
        rgb1=[0.62, 0.58, 0.52],
        rgb2=[0.55, 0.5, 0.45],
        width=256,
        height=256,
    )
    mat = spec.add_material(name="floor_mat", texrepeat=[6, 6], reflectance=0.05)
    mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = tex.name
    center = layout.ROOM_CENTER
    half = layout.ROOM_HALF + 0.6
    spec.worldbody.add_geom(
        name=FLOOR_GEOM,
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[half[0], half[1], 0.05],
        pos=[center[0], center[1], 0],
        material="floor_mat",
    )
    wall_rgba = [0.86, 0.85, 0.8, 1]
    spec.worldbody.add_geom(
        name="wall_back",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[0.05, half[1], 1.3],
        pos=[center[0] + half[0] + 0.05, center[1], 1.3],
        rgba=wall_rgba,
    )
    spec.worldbody.add_geom(
        name="wall_left",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[half[0], 0.05, 1.3],
        pos=[center[0], center[1] + half[1] + 0.05, 1.3],
        rgba=wall_rgba,
    )
    spec.worldbody.add_light(
        name="sun",
        pos=[center[0], center[1], 3.5],
        dir=[0.2, 0.1, -1],
        type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
        diffuse=[0.6, 0.6, 0.6],
        specular=[0.1, 0.1, 0.1],
        castshadow=True,
    )
    spec.worldbody.add_light(
        name="fill", pos=[-1.0, -1.0, 2.5], dir=[0.5, 0.4, -0.6], diffuse=[0.35, 0.35, 0.35], castshadow=False
    )

    focus = np.mean(
        [p.world_center() for p in placed.values() if p.role != ObjectRole.CLUTTER]
        or [np.array([1.0, 0, 0.4])],
        axis=0,
    )
    focus[2] = min(max(focus[2], 0.2), 0.8)
    # Front camera: behind the robot as seen from the task objects, raised, turned 30 degrees, so
    # the robot stands in the foreground and the scene behind it.
    away = lay.base[:2] - focus[:2]
    dist = float(np.linalg.norm(away))
    away = away / dist if dist > 1e-6 else np.array([-1.0, 0.0])
    c, s = math.cos(0.5), math.sin(0.5)
    away = np.array([c * away[0] - s * away[1], s * away[0] + c * away[1]])
    eye = np.r_[focus[:2] + away * (dist + 1.0), 1.9]
    spec.worldbody.add_camera(name="front", pos=eye.tolist(), xyaxes=_look_at_xyaxes(eye, focus), fovy=60)
    top_eye = np.array([focus[0], focus[1] - 0.01, 3.3])
    spec.worldbody.add_camera(name="top", pos=top_eye.tolist(), xyaxes=[0, -1, 0, 1, 0, 0], fovy=55)

    loose, parts = [], []
    for p in placed.values():
        body = spec.worldbody.add_body(name=p.name, pos=p.pos.tolist(), quat=p.quat)
        if p.support_geom is not None:
            furniture.emit(p.support_geom, body, rng)
            continue
        root = p.asset.attach(body, f"{p.name}/")
        if not p.fixed:
            body.add_freejoint(name=f"{p.name}/free")
            loose.append((p.name, root.name))
        parts.extend(_articulated_bodies(root))
        if not p.fixed:
            # Rolling and torsional friction (condim 6): a needle or pencil must not roll for ever.
            # A 1 mm contact margin stops needles and coins tunnelling into a table top. Their
            # contacts are stiffer than the 20 ms default (priority makes theirs win): with it a
            # needle set down in a box sank past the middle of the 8 mm bottom and was pushed out
            # underneath.
            for geom in _geoms_below(root):
                geom.condim = 6
                geom.friction = [max(geom.friction[0], 0.8), 0.01, 0.002]
                geom.margin = max(geom.margin, 0.001)
                geom.priority = 1
                geom.solref = [LOOSE_SOLREF, 1.0]
    # Suction can also hold a door, lid or drawer, so primitives can pull parts open or lift them shut.
    robot_model.add_suction_welds(spec, [n for n, _ in loose] + parts, [r for _, r in loose] + parts)
    task_objects = [p for p in placed.values() if p.role != ObjectRole.CLUTTER]
    add_observation_sensors(
        spec,
        list(robot.ROBOT_JOINTS),
        [p.name for p in task_objects],
        [f"{p.name}/{j.name}" for p in task_objects if p.asset is not None for j in p.asset.joints],
    )
    spec.add_key(name="init")
    return spec


def _articulated_bodies(body) -> list[str]:
    """Names of the bodies under ``body`` that move on a hinge or slide joint (doors, lids, drawers)."""
    import mujoco

    out = []
    if any(j.type in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE) for j in body.joints):
        out.append(body.name)
    for child in body.bodies:
        out.extend(_articulated_bodies(child))
    return out


def _geoms_below(body) -> list:
    out = list(body.geoms)
    for child in body.bodies:
        out.extend(_geoms_below(child))
    return out


def _latch_switched_on(model, placed: dict[str, Placed], mjspec) -> None:
    """A spring-returned button set to 'on' is modelled as latched (a kettle's switch stays down):
    its return spring is removed so the hazard state persists; friction keeps it where it is set."""
    import mujoco

    for p in placed.values():
        if p.asset is None:
            continue
        for j in p.asset.joints:
            value = p.joint_values.get(j.name)
            if value is None or abs(value - j.closed_value) < 1e-9:
                continue
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{p.name}/{j.name}")
            if jid < 0 or model.jnt_stiffness[jid] <= 0:
                continue
            stiffness = float(model.jnt_stiffness[jid])
            model.jnt_stiffness[jid] = 0.0
            dof = model.jnt_dofadr[jid]
            hold = stiffness * abs(value - j.closed_value) * 1.5
            model.dof_frictionloss[dof] = max(model.dof_frictionloss[dof], hold)
            sj = mjspec.joint(f"{p.name}/{j.name}")
            sj.stiffness = [0.0] * len(sj.stiffness) if hasattr(sj.stiffness, "__len__") else 0.0
            sj.frictionloss = float(model.dof_frictionloss[dof])


def _hold_gravity_hinges(model, placed: dict[str, Placed], mjspec) -> None:
    """Give horizontal-axis hinges (lids, laptop screens) enough friction to stay where they are set.

    Real lids and oven doors are stiff enough to stay open; a frictionless model would slam shut
    during settling and the hazard would vanish. The friction is 1.3x the gravity torque of the
    moving part, so the robot can still close it.
    """
    import mujoco

    g = abs(model.opt.gravity[2])
    for p in placed.values():
        if p.asset is None:
            continue
        for j in p.asset.joints:
            vertical_slide = j.type == "slide" and abs(j.axis[2]) > 0.7
            if not vertical_slide and (j.type != "hinge" or abs(j.axis[2]) > 0.7):
                continue
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{p.name}/{j.name}")
            if jid < 0:
                continue
            body = model.jnt_bodyid[jid]
            mass = model.body_subtreemass[body]
            lever = (
                float(np.linalg.norm(model.body_ipos[body]))
                + 0.5 * float(np.max(model.body_inertia[body]) / max(mass, 1e-6)) ** 0.5
            )
            friction = 1.3 * mass * g * (1.0 if vertical_slide else max(lever, 0.02))
            dof = model.jnt_dofadr[jid]
            model.dof_frictionloss[dof] = max(model.dof_frictionloss[dof], friction)
            mjspec.joint(f"{p.name}/{j.name}").frictionloss = float(model.dof_frictionloss[dof])


def _set_joints(model, data, placed: dict[str, Placed]) -> None:
    for p in placed.values():
        for jname, value in p.joint_values.items():
            data.joint(f"{p.name}/{jname}").qpos[0] = value


# ============================================================================ attempt


def _attempt(task: TaskProposal, seed: int, settings: Settings, attempt: int, hints=None,
             hazard_free: bool = False) -> Built:
    import mujoco

    from anomalygen.scene import validate as val
    from anomalygen.scene.graph import scene_graph

    rng = item_rng(seed, task.id, attempt)
    hints = hints.model_copy(deep=True) if hints is not None else None  # each attempt records its own
    lay, bindings, placed = _plan(task, settings, rng, hints, hazard_free)
    notes = _hint_notes(hints, lay)
    mjspec = _compose(lay, placed, settings, rng)
    model = mjspec.compile()
    data = mujoco.MjData(model)
    _hold_gravity_hinges(model, placed, mjspec)
    _latch_switched_on(model, placed, mjspec)
    robot.set_home(model, data, tuple(lay.base))
    _set_joints(model, data, placed)
    mujoco.mj_forward(model, data)
    spec = _scene_spec(task, seed, lay, placed, bindings, model, data)
    overlap = val.initial_overlap(model, data, spec)
    if overlap is not None:
        report = ValidationReport(ok=False, reason=overlap, checks=notes)
        return Built(spec, mjspec, model, data, report, None)
    nsteps = max(1, int(round(settings.build.settle_s / model.opt.timestep)))
    mujoco.mj_step(model, data, nstep=nsteps)
    if val.max_loose_speed(model, data, placed) > val.MAX_LIN_VEL:
        mujoco.mj_step(model, data, nstep=nsteps)  # something still rolls: give it one more settle
    mujoco.mj_forward(model, data)
    spec = _scene_spec(task, seed, lay, placed, bindings, model, data)
    graph = scene_graph(model, data, spec)
    hc = _kb().hazard_classes.get(task.hazard_class)
    report = val.validate(model, data, spec, graph, None if hazard_free else hc)
    if hazard_free and report.ok:
        report = _check_hazard_free(report, graph, task.hazard_class)
    report.checks = notes + report.checks
    return Built(spec, mjspec, model, data, report, graph)


def _check_hazard_free(report: ValidationReport, graph, hazard_class: str) -> ValidationReport:
    """A hazard-free variant must not show the task's hazard anywhere once settled."""
    from anomalygen.scene.truth import class_matches

    still = sorted(obj for cls, obj, _ in class_matches(graph, _kb()) if cls == hazard_class)
    check = ValidationCheck(name="hazard_free", passed=not still,
                            detail=f"{hazard_class} still holds for {', '.join(still)}" if still else "made safe")
    report.checks.append(check)
    if still:
        report.ok, report.reason = False, check.detail
    return report


def _hint_notes(hints, lay: Layout) -> list[ValidationCheck]:
    """Every correction to an engine's sizes and positions, for the validation report (none offline)."""
    if hints is None:
        return []
    done = {c.name for c in lay.corrections}
    notes = list(hints.checks) + list(lay.corrections)
    notes += [
        ValidationCheck(name=f"position:{name}", passed=True, detail="placed by its scenario placement (on or in "
                        "another object), not at the proposed floor spot")
        for name in lay.preferred if f"position:{name}" not in done
    ]
    return notes


def _scene_spec(task, seed, lay: Layout, placed: dict[str, Placed], bindings, model, data) -> SceneSpec:
    objects = []
    for p in placed.values():
        body = data.body(p.name)
        if p.asset is not None:
            ref = p.asset.ref
            size = float(p.asset.size)
            joints = [
                JointState(
                    name=f"{p.name}/{j.name}",
                    label=select.kb_label(j.label),
                    type=j.type,
                    value=float(data.joint(f"{p.name}/{j.name}").qpos[0]),
                    range=(float(j.range[0]), float(j.range[1])),
                    closed_value=float(j.closed_value),
                )
                for j in p.asset.joints
            ]
        else:
            s = p.support_geom
            ref = AssetRef(
                asset_id=f"support-{s.kind}-{s.top:.3f}",
                category=s.category,
                source=AssetSource.PROCEDURAL,
                params={"kind": s.kind, "half": list(s.half), "top": s.top, "thickness": s.thickness},
            )
            size = s.size
            joints = []
        objects.append(
            PlacedObject(
                name=p.name,
                asset=ref,
                role=p.role,
                size=size,
                pos=[float(v) for v in body.xpos],
                quat=[float(v) for v in body.xquat],
                support=p.support,
                inside=p.inside,
                joint_states=joints,
                fixed=p.fixed,
            )
        )
    return SceneSpec(
        scene_id=scene_id_for(task.id),
        task_id=task.id,
        room=task.scenario.room,
        seed=seed,
        objects=objects,
        robot_base=[float(v) for v in lay.base],
        bindings=bindings,
    )


def scene_id_for(task_id: str) -> str:
    """An opaque scene id: task ids may carry words of the task, which detection must not see."""
    return f"scene_{stable_hash('scene', task_id) & 0xFFFFFFFFFF:010x}"


# ============================================================================ public entry


def build_scene(task: TaskProposal, *, seed: int, settings: Settings, out_dir: Path, hints=None,
                hazard_free: bool = False) -> SceneSpec:
    """Build, settle, validate, repair and write one scene; raises ItemFailed with a one-line reason.

    ``hazard_free`` builds the task's object in its safe state (``scene/mix.py``); its truth.json then
    lists only what the settled scene really shows.

    ``hints`` come from a non-default scene engine (``scene/llm_engine.py``); None keeps the draws."""
    attempts = settings.build.repair_attempts + 1
    reason = "no attempt made"
    built = None
    for attempt in range(attempts):
        try:
            built = _attempt(task, seed, settings, attempt, hints, hazard_free)
        except ItemFailed as exc:
            reason = str(exc)
            log.debug("%s attempt %d: %s", task.id, attempt, reason)
            continue
        if built.report.ok and settings.llm.configured and settings.llm.vision:
            try:
                _vlm_check(task, built, settings)
            except ItemFailed as exc:
                built.report.ok = False
                built.report.reason = str(exc)
        if built.report.ok:
            built.report.repairs = attempt
            break
        reason = built.report.reason
        log.debug("%s attempt %d: %s", task.id, attempt, reason)
        built = None
    if built is None:
        raise ItemFailed(f"no valid scene after {attempts} attempt(s): {reason}")
    return write_outputs(built, settings, Path(out_dir), hazard_class=None if hazard_free else task.hazard_class)


def _vlm_check(task, built: Built, settings: Settings) -> None:
    from anomalygen.scene.render import SceneRenderer, png_bytes
    from anomalygen.scene.verify import verify_with_vlm

    with SceneRenderer(built.model, settings.build.render_width, settings.build.render_height) as r:
        png = png_bytes(r.render(built.data, "front"))
    verify_with_vlm(task, built.spec, png, settings)
    built.report.checks.append(
        ValidationCheck(name="vlm_verification", passed=True, detail=settings.llm.model or "")
    )


def write_outputs(built: Built, settings: Settings, out_dir: Path, *, hazard_class: str | None = None) -> SceneSpec:
    """scene.xml, renders, scene_graph.json, the hidden truth.json, scene.json last.

    ``hazard_class`` is the hazard the builder set up (None for a hazard-free scene)."""
    from anomalygen.scene.render import SceneRenderer, png_bytes
    from anomalygen.scene.truth import TRUTH_FILE, hazard_manifest

    out_dir.mkdir(parents=True, exist_ok=True)
    model, data, mjspec = built.model, built.data, built.mjspec
    key = mjspec.key("init")
    key.qpos = data.qpos.copy()
    key.qvel = np.zeros(model.nv)
    key.ctrl = data.ctrl.copy()
    if model.nmocap:
        key.mpos = data.mocap_pos.flatten().copy()
        key.mquat = data.mocap_quat.flatten().copy()
    files = {"xml": "scene.xml", "spec": "scene.json", "graph": "scene_graph.json"}
    _write_xml(mjspec, out_dir)
    with SceneRenderer(model, settings.build.render_width, settings.build.render_height) as r:
        for cam in CAMERAS:
            atomic_write_bytes(out_dir / f"render_{cam}.png", png_bytes(r.render(data, cam)))
            files[f"render_{cam}"] = f"render_{cam}.png"
    spec = built.spec.model_copy(update={"validation": built.report, "files": files})
    write_model(out_dir / "scene_graph.json", built.graph)
    write_model(out_dir / TRUTH_FILE, hazard_manifest(spec, hazard_class, built.graph, _kb()))
    write_model(out_dir / "scene.json", spec)  # last: its presence marks the scene done
    return spec


def _write_xml(mjspec, out_dir: Path) -> None:
    """scene.xml with robot meshes under assets/franka, loadable from any working directory."""
    src = robot_model.franka_assets_dir() / "meshes"
    dst = out_dir / "assets" / "franka"
    for rel in robot_model.mesh_files():
        target = dst / rel
        if target.exists():
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        try:
            os.link(src / rel, target)  # hard link: no copy of the 6 MB of meshes per scene
        except OSError:
            shutil.copyfile(src / rel, target)
    xml = mjspec.to_xml()
    xml = xml.replace(f'meshdir="{src}"', 'meshdir="assets/franka"', 1)
    if 'meshdir="assets/franka"' not in xml:  # pragma: no cover - MuJoCo changed its XML writer
        raise RuntimeError("could not relocate the robot mesh folder in scene.xml")
    atomic_write_text(out_dir / "scene.xml", xml)
