"""One chosen object as a placed instance, and where other things can go on it.

An ``asset_choice.Chosen`` becomes a ``layout.Placed`` (its box, front and the sweep of open doors); a holder's
top surface and biggest cavity are given in world coordinates, and a container's room says what lies
flat in it. The margins every placement keeps from a support's edge are defined here too.
"""

from __future__ import annotations

import math

import numpy as np

from anomalygen.errors import ItemFailed
from anomalygen.scene import asset_choice, furniture, layout
from anomalygen.scene.layout import Placed
from anomalygen.schema import DOOR, DRAWER, ObjectRole, part_labels

INWARD = 0.13  # m kept from a support's edge by things that are not the edge hazard
HAZARD_NEAR_SIDE = 0.4  # m: the hazard's centre at most this far from the robot-facing edge (arm's reach)


def instance_name(catalogue: str, used: set[str]) -> str:
    base = catalogue.lower()
    i = 0
    while f"{base}_{i}" in used:
        i += 1
    name = f"{base}_{i}"
    used.add(name)
    return name


def renumber_by_position(lay: layout.Layout, placed: dict[str, Placed],
                         bindings: dict[str, str]) -> tuple[dict[str, Placed], dict[str, str]]:
    """Number each category's instances by where they stand (x, then y, then z), not in the order the
    builder chose them; returns the instances in name order and the bindings renamed.

    Why: names are handed out as objects are chosen, the hazard first, so ``kitchen_knife_0`` beside a
    near-miss ``kitchen_knife_1`` told the robot which knife was at fault, and the order of the objects
    (in scene.json, the scene graph, the model's bodies and sensors) told it which was the support.
    """
    groups: dict[str, list[Placed]] = {}
    for p in placed.values():
        groups.setdefault(p.name.rsplit("_", 1)[0], []).append(p)
    rename: dict[str, str] = {}
    for base, members in groups.items():
        members.sort(key=lambda p: tuple(np.round(p.world_center(), 4)))
        rename.update({p.name: f"{base}_{i}" for i, p in enumerate(members)})

    def new(ref: str | None) -> str | None:
        if ref is None:
            return None
        name, colon, rest = ref.partition(":")
        return rename.get(name, name) + colon + rest

    for p in placed.values():
        p.name, p.support, p.inside = rename[p.name], new(p.support), new(p.inside)
    lay.preferred = {rename.get(k, k): v for k, v in lay.preferred.items()}
    for check in lay.corrections:
        kind, _, name = check.name.partition(":")
        check.name = f"{kind}:{rename.get(name, name)}"
    return {p.name: p for p in sorted(placed.values(), key=lambda p: p.name)}, {
        var: rename.get(name, name) for var, name in bindings.items()}


def _front(asset) -> np.ndarray | None:
    """Local direction the asset's doors/drawers open to (the catalogue convention is -y), the side
    the asset declares it is worked from (a real stove's control knobs), or -y for an asset reached
    from its front only (a bookcase's shelves, the procedural stove's knobs)."""
    if getattr(asset, "front", None) is not None:
        return np.asarray(asset.front, float)
    if any(part_labels.is_closure(j.label) for j in asset.joints) or asset.cavities or asset.front_access:
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
        elif part_labels.swings(j.label):
            out = max(out, min(float(max(ext[0], ext[2] if abs(j.axis[2]) < 0.5 else ext[0])), 1.0))
    return out


SWING_MAX = 0.9  # m: the most room kept clear in front of shut doors/drawers
#: the roles of objects the robot may have to open (to put the hazard in, or take it out)
OPENED_ROLES = (ObjectRole.CONTAINER, ObjectRole.TARGET, ObjectRole.HAZARD)


def _swing(asset) -> float:
    """Room a shut door/drawer needs in front to open: a drawer its travel, a side-hinged door its
    width (the asset's width shared among its side-hinged doors), a door hinged at its foot its
    height; capped at ``SWING_MAX``."""
    ext = asset.aabb[1] - asset.aabb[0]
    side = [j for j in asset.joints if j.type == "hinge" and j.label == DOOR and abs(j.axis[2]) >= 0.5]
    out = 0.0
    for j in asset.joints:
        if j.label not in (DOOR, DRAWER):
            continue
        if j.type == "slide":
            out = max(out, abs(j.range[1] - j.range[0]) + 0.02)
        elif abs(j.axis[2]) >= 0.5:
            out = max(out, float(ext[0]) / len(side))
        else:
            out = max(out, float(ext[2]))
    return min(out, SWING_MAX)


def placed_instance(chosen: asset_choice.Chosen) -> Placed:
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
        states=list(chosen.states),
        front=_front(chosen.asset),
    )
    p.sweep = _sweep(chosen.asset, chosen.joint_values)
    if chosen.role in OPENED_ROLES and p.front is not None:
        p.swing = _swing(chosen.asset)
    return p


def placed_support(kind: str, name: str, rng, role=ObjectRole.SUPPORT) -> Placed:
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


def surface_of(holder: Placed):
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


def cavity_front(holder: Placed, cav) -> np.ndarray | None:
    """World direction out of a cavity's front opening (an asset's front is its -y), None if open on top."""
    if cav.opening != "front":
        return None
    return np.array([math.sin(holder.yaw), -math.cos(holder.yaw)])


def cavity_world(holder: Placed):
    asset = holder.asset
    if not asset.cavities:
        raise ItemFailed(f"{holder.catalogue} has no interior to put things in")
    cav = asset_choice.biggest_cavity(asset)
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
