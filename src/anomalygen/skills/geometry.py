"""Geometry queries on a loaded scene: boxes, tops, openings, footprints, free spots, part points.

They read the episode's model, data, perceived spec and the skills' memory of what was opened
(:class:`~anomalygen.skills.episode.Episode`), never move anything, and import neither the primitives
nor the part skills, so both can use them without an import cycle.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from anomalygen.mjgeom import geom_world_aabbs
from anomalygen.robot.frames import subtree_geoms
from anomalygen.world.tops import on_fixed_frame

if TYPE_CHECKING:
    from anomalygen.skills.episode import Episode

HINGE, SLIDE = 3, 2  # mujoco.mjtJoint values
PRE_CONTACT = 0.03  # metres off the surface before the straight approach along the normal


def joint_motion_direction(model, data, joint: str, point: np.ndarray) -> np.ndarray:
    """Unit world direction in which ``point`` (on the part) moves when the joint value increases."""
    import mujoco

    j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
    axis = data.xaxis[j]
    if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE:
        return axis / np.linalg.norm(axis)
    v = np.cross(axis, np.asarray(point) - data.xanchor[j])
    return v / (np.linalg.norm(v) + 1e-12)


def grasp_points(ep: Episode, obj: str, n: int = 3) -> list[np.ndarray]:
    """Up to ``n`` points to put the cup on, best first: the tops of the object's highest, widest
    collision geoms, then the centre of its box's top. A pair of pliers or glasses has nothing
    under the centre of its box, so the box alone sends the cup into a gap."""

    drv = ep.driver
    m = drv.model
    lo, hi = drv.aabb(obj)
    glo, ghi = geom_world_aabbs(m, drv.data)
    mask = subtree_geoms(m, drv.body_id(obj)) & (m.geom_contype | m.geom_conaffinity).astype(bool)
    cands = []
    for g in np.flatnonzero(mask):
        area = float(np.prod(ghi[g, :2] - glo[g, :2]))
        top = float(ghi[g, 2])
        if top < hi[2] - 0.03:
            continue  # well below the top: the cup would meet something else first
        cands.append((top - hi[2] + 3.0 * np.sqrt(area), np.array([*(glo[g, :2] + ghi[g, :2]) / 2, top])))
    cands.sort(key=lambda c: -c[0])
    pts: list[np.ndarray] = []
    for _, p in cands:
        if all(np.linalg.norm(p[:2] - q[:2]) > 0.02 for q in pts):
            pts.append(p)
    centre = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2]])
    if all(np.linalg.norm(centre[:2] - q[:2]) > 0.02 for q in pts):
        pts.append(centre)
    return pts[:n]


def opened_drawer(ep: Episode, region: str) -> str | None:
    """The drawer joint that ``open_for_access`` pulled out of ``region``, if any."""
    drv = ep.driver
    return next((j for j in ep.memory.opened.get(region, []) if drv.model.jnt_type[drv.model.joint(j).id] == SLIDE),
                None)


def rim_z(ep: Episode, region: str) -> float:
    """Height the bottom of an object carried into ``region`` must clear: the top of the drawer pulled
    out of it, else the top of its opening."""
    drv = ep.driver
    drawer = opened_drawer(ep, region)
    if drawer is not None:
        return float(drv.aabb(drv.joint_body(drawer))[1][2])
    return float(opening(ep, region)[1][2])


def drop_point(ep: Episode, region: str, obj: str) -> np.ndarray:
    """Where to hold the object's bottom before release: above the opening of the container's carcass
    (an open lid's own box does not count), inside an opened drawer's exposed part, or above the
    centre of a support's top."""
    drv = ep.driver
    drawer = opened_drawer(ep, region)
    if drawer is not None:
        dlo, dhi = drv.aabb(drv.joint_body(drawer))
        clo, chi = static_box(ep, region)
        axis = np.abs(drv.data.xaxis[drv.model.joint(drawer).id])
        k = int(np.argmax(axis[:2]))
        centre = (dlo + dhi) / 2
        # the stretch of the drawer that sticks out of the carcass, along the slide axis
        if dhi[k] > chi[k]:
            centre[k] = (max(dlo[k], chi[k]) + dhi[k]) / 2
        elif dlo[k] < clo[k]:
            centre[k] = (dlo[k] + min(dhi[k], clo[k])) / 2
        top = np.array([centre[0], centre[1], dhi[2] + 0.03])
        floor = floor_below(ep, top, obj)
        return top if floor is None else np.array([centre[0], centre[1], floor - 0.01])
    lo, hi = opening(ep, region)
    centre = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2] + 0.04])
    # Set the object down inside rather than drop it from the rim: the contacts are soft (20 ms), so
    # a needle or a flat wrapper falling even 2 cm sinks past the middle of an 8 mm bottom and is
    # pushed out underneath. The floor inside is found by a ray; the lowering stops at first touch.
    floor = floor_below(ep, centre, obj)
    if floor is not None:
        centre[2] = min(max(floor - 0.01, hi[2] - MAX_REACH_IN), hi[2] + 0.04)
    return centre


MAX_REACH_IN = 0.5  # m the held object's bottom may go below a container's rim


def floor_below(ep: Episode, point: np.ndarray, obj: str) -> float | None:
    """Height of the first surface under ``point`` (the held object and the robot ignored)."""
    import mujoco

    drv = ep.driver
    m, d = drv.model, drv.data
    skip = subtree_geoms(m, drv.body_id(obj)) | np.isin(np.arange(m.ngeom), list(drv._robot_geoms))
    start = np.asarray(point, dtype=float).copy()
    geomid = np.zeros(1, dtype=np.int32)
    for _ in range(8):  # step past ignored geoms
        dist = mujoco.mj_ray(m, d, start, np.array([0.0, 0.0, -1.0]), None, 1, -1, geomid)
        if dist < 0:
            return None
        hit = start[2] - dist
        if not skip[int(geomid[0])]:
            return float(hit)
        start[2] = hit - 1e-4
    return None


def top_rect(ep: Episode, support: str) -> tuple[np.ndarray, np.ndarray]:
    """World box of a support's top board (not the legs' footprint), its height the top's.

    Only solid geoms of the support's fixed frame count: the top edge of a cabinet door swung open
    reaches the same height, and counting it moved the middle of the "top" out over the doorway (a
    dumbbell taken down onto the Franka Kitchen cabinet was set on its front edge)."""

    drv = ep.driver
    m = drv.model
    lo, hi = drv.aabb(support)
    glo, ghi = geom_world_aabbs(m, drv.data)
    root = drv.body_id(support)

    top_geoms = [g for g in range(m.ngeom) if m.body(int(m.geom_bodyid[g])).name.startswith(support + "/")
                 and ghi[g, 2] > hi[2] - 0.01 and (m.geom_contype[g] or m.geom_conaffinity[g])
                 and on_fixed_frame(m, int(m.geom_bodyid[g]), root)]
    if top_geoms:
        lo = np.min(glo[top_geoms], axis=0)
        hi = np.array([*np.max(ghi[top_geoms], axis=0)[:2], hi[2]])
    return lo, hi


def free_spot(ep: Episode, support: str, obj: str, *, edge_margin: float = 0.2, turned: bool = True,
              away: tuple[np.ndarray, np.ndarray, float] | None = None, square: bool = False) -> np.ndarray:
    """The drop point of :func:`rated_spot` alone."""
    return rated_spot(ep, support, obj, edge_margin=edge_margin, turned=turned, away=away, square=square)[0]


def rated_spot(ep: Episode, support: str, obj: str, *, edge_margin: float = 0.2, turned: bool = True,
               away: tuple[np.ndarray, np.ndarray, float] | None = None,
               crosswise: bool = False, square: bool = False) -> tuple[np.ndarray, float, int]:
    """(drop point, its edge clearance in m, how many other things it lands on). The point is on the
    support's top, keeps ``edge_margin`` from its edges and misses the other things standing there
    (a book in the middle of the table would leave the object perched half on it), nearest the
    centre; the centre when the top is too small for the margin. The clearance and the count say
    whether the best the top offers is good enough (a crowded or narrow top may have no spot clear
    of both its edges and its things).

    ``turned``: the object will be turned to lie along the top's long side (``move_to`` does that
    for objects with a long side); otherwise it keeps its present orientation. ``away``: (lo, hi,
    gap) of a box the object must end at least ``gap`` from, horizontally (a candle moved away from
    the curtains); falling short costs more than anything else. ``crosswise`` (with ``turned``
    False): rated as if turned a quarter turn from how it rests (a dumbbell set across a crowded
    table, where lengthwise the clear room is near an edge). ``square``: it may end either way round,
    so it is rated as a square of its half length (``move_away`` checks the distance that way)."""
    drv = ep.driver

    lo, hi = top_rect(ep, support)
    if turned:
        _, a, b = footprint(ep, obj)
        half = np.array([a, b]) if hi[0] - lo[0] >= hi[1] - lo[1] else np.array([b, a])
    else:
        olo, ohi = drv.aabb(obj)
        half = (ohi[:2] - olo[:2]) / 2
        if crosswise:
            half = half[::-1]
    if square:
        half = np.full(2, float(footprint(ep, obj)[1]))
    others = []
    for o in ep.spec.objects:
        if o.name in (obj, support):
            continue
        blo, bhi = drv.aabb(o.name)
        if bhi[2] > hi[2] - 0.01 and blo[2] < hi[2] + 0.3:
            others.append((blo[:2], bhi[:2]))
    centre = (lo[:2] + hi[:2]) / 2
    inset = np.minimum(half + 0.02, (hi[:2] - lo[:2]) / 2)
    best, best_score, best_edge, best_hits = centre, np.inf, 0.0, 0
    # Score a 31 x 31 grid (a 4 cm step can miss the one clear spot on a crowded table): landing on
    # something else (nearer it than HIT_GAP) costs most, then ending within NEAR_EDGE of an edge
    # (the hazard itself), then standing closer than CLEAR_GAP to something (on a crowded counter the
    # one spot clear of the edges may be 1-2 cm beside a tissue box), then falling short of the wider
    # margin, then distance from the centre.
    for x in np.linspace(lo[0] + inset[0], hi[0] - inset[0], 31):
        for y in np.linspace(lo[1] + inset[1], hi[1] - inset[1], 31):
            p = np.array([x, y])
            hits = sum(bool(np.all(p + half > a - HIT_GAP) and np.all(p - half < b + HIT_GAP)) for a, b in others)
            close = sum(bool(np.all(p + half > a - CLEAR_GAP) and np.all(p - half < b + CLEAR_GAP)) for a, b in others)
            edge = float(np.min(np.minimum(p - half - lo[:2], hi[:2] - p - half)))
            score = (hits * 10.0 + 20.0 * max(0.0, NEAR_EDGE + 0.02 - edge) + 0.3 * close
                     + 5.0 * max(0.0, edge_margin - edge) + 0.1 * float(np.linalg.norm(p - centre)))
            if away is not None:
                score += 100.0 * max(0.0, away[2] - box_gap((p - half, p + half), away))
            if score < best_score:
                best, best_score, best_edge, best_hits = p, score, edge, hits
    # set down until it touches: a dropped globe topples
    return np.array([best[0], best[1], hi[2] - 0.01]), best_edge, best_hits


def opening(ep: Episode, region: str) -> tuple[np.ndarray, np.ndarray]:
    """The box above which a dropped object falls into ``region``: the carcass's top rectangle, minus
    the strip that a half-open lid still hangs over (the lid swings about a horizontal axis, so it
    covers the side of the opening next to its hinge). The strip is cut across the direction the lid
    swings in, which need not be a world axis (a trash can stands turned), so the box returned is the
    world box of what is left of the top rectangle."""
    drv = ep.driver
    if not ep.memory.opened.get(region):
        return drv.aabb(region)
    lo, hi = (v.copy() for v in static_box(ep, region))
    m = drv.model
    poly = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])
    for jn in ep.memory.opened[region]:
        j = m.joint(jn).id
        if m.jnt_type[j] != HINGE:
            continue
        axis = drv.data.xaxis[j]
        u = np.array([-axis[1], axis[0]])  # horizontal direction the part swings along
        if np.linalg.norm(u) < 0.5:
            continue  # a vertical hinge: a door, beside the opening rather than over it
        u = u / np.linalg.norm(u)
        pts = body_corners(ep, int(m.jnt_bodyid[j]))[:, :2] @ u
        plo, phi = float(pts.min()), float(pts.max())
        along = poly @ u
        if phi + LID_CLEARANCE <= along.min() or plo - LID_CLEARANCE >= along.max():
            continue  # swung clear of the opening (a lid standing at the rim is still in the way)
        # keep the wrist above the held object clear of the lid's edge as well, where the strip allows
        low_side = plo - along.min() >= along.max() - phi
        for margin in (LID_CLEARANCE, 0.0):
            cut = _clip(poly, -u, -(plo - margin)) if low_side else _clip(poly, u, phi + margin)
            if len(cut) >= 3 and np.ptp(cut @ u) > MIN_STRIP:
                break
        poly = cut
        if len(poly) < 3:
            c = (lo[:2] + hi[:2]) / 2
            poly = np.array([c, c + 1e-3])
    lo[:2], hi[:2] = poly.min(axis=0), poly.max(axis=0)
    hi[:2] = np.maximum(hi[:2], lo[:2] + 1e-3)
    return lo, hi


LID_CLEARANCE = 0.05  # m kept between an open lid's edge and the drop strip, for the wrist
MIN_STRIP = 0.12  # m: a strip narrower than this (a small bin) keeps no clearance: the object must fit


def lid_free_side(ep: Episode, region: str) -> np.ndarray | None:
    """Horizontal unit direction from the hinge of ``region``'s opened lid across its opening: the
    side to work from, where the lid leans away from the arm (from the hinge side the wrist meets the
    lid's underside and knocks it shut). None without one such lid (flaps on opposite sides cancel)."""
    drv = ep.driver
    m, d = drv.model, drv.data
    lo, hi = static_box(ep, region)
    centre = (lo[:2] + hi[:2]) / 2
    total = np.zeros(2)
    for jn in ep.memory.opened.get(region, []):
        j = m.joint(jn).id
        axis = d.xaxis[j]
        if m.jnt_type[j] != HINGE or abs(axis[2]) > 0.7:
            continue
        u = np.array([-axis[1], axis[0]])
        u = u / (np.linalg.norm(u) + 1e-12)
        total += u * np.sign(float(np.dot(centre - d.xanchor[j][:2], u)))
    n = float(np.linalg.norm(total))
    return total / n if n > 0.5 else None


def _clip(poly: np.ndarray, n: np.ndarray, c: float) -> np.ndarray:
    """The part of a convex polygon where p.n >= c (one Sutherland-Hodgman pass)."""
    out = []
    for i in range(len(poly)):
        a, b = poly[i], poly[(i + 1) % len(poly)]
        da, db = float(a @ n) - c, float(b @ n) - c
        if da >= 0:
            out.append(a)
        if da * db < 0:
            out.append(a + (b - a) * da / (da - db))
    return np.array(out) if out else np.zeros((0, 2))


def body_corners(ep: Episode, body: int) -> np.ndarray:
    """World corners of the boxes of a body's collision geoms (all its geoms if none collide)."""
    drv = ep.driver
    m, d = drv.model, drv.data
    geoms = [g for g in range(m.ngeom) if m.geom_bodyid[g] == body]
    geoms = [g for g in geoms if m.geom_contype[g] or m.geom_conaffinity[g]] or geoms
    box = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    pts = [(box * m.geom_aabb[g, 3:] + m.geom_aabb[g, :3]) @ d.geom_xmat[g].reshape(3, 3).T + d.geom_xpos[g]
           for g in geoms]
    return np.concatenate(pts)


def long_axis_yaw(ep: Episode, obj: str) -> float:
    """Yaw of the held object's longest horizontal extent (principal axis of its geoms' corners)."""
    return footprint(ep, obj)[0]


def footprint(ep: Episode, obj: str) -> tuple[float, float, float]:
    """(yaw of the long side, half length, half width) of the object seen from above."""

    drv = ep.driver
    m, d = drv.model, drv.data
    mask = subtree_geoms(m, drv.body_id(obj))
    pts = []
    for g in np.flatnonzero(mask):
        c, h = m.geom_aabb[g, :3], m.geom_aabb[g, 3:]
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h + c
        pts.append(corners @ d.geom_xmat[g].reshape(3, 3).T + d.geom_xpos[g])
    xy = np.concatenate(pts)[:, :2]
    xy = xy - xy.mean(axis=0)
    w, v = np.linalg.eigh(xy.T @ xy)
    major = v[:, int(np.argmax(w))]
    minor = np.array([-major[1], major[0]])
    along, across = xy @ major, xy @ minor
    return (float(np.arctan2(major[1], major[0])), float(np.ptp(along)) / 2, float(np.ptp(across)) / 2)


def box_gap(a, b) -> float:
    """Horizontal gap between two boxes given as (lo, hi) with at least x and y (0 when they overlap)."""
    gaps = [max(0.0, float(a[0][i]) - float(b[1][i]), float(b[0][i]) - float(a[1][i])) for i in (0, 1)]
    return float(np.hypot(*gaps))


HIT_GAP = 0.01  # m: a set-down spot nearer another object's box than this counts as landing on it
CLEAR_GAP = 0.03  # m kept from other objects where the top leaves room
NEAR_EDGE = 0.15  # m: the knowledge base's near_edge distance for fragile things (move_fragile_from_edge)


def surface_centre_of(ep: Episode, obj: str) -> str | None:
    """The support ``obj`` rests on now (the live scene graph's ``on``), None on the floor. Not the
    spec's: an earlier step may have moved it (a laptop carried from the sink to a table, then set
    back from that table's edge)."""
    on = [r.object for r in ep.graph().relations if r.subject == obj and r.predicate == "on" and r.object]
    return on[0].split(":")[0] if on else None


def part_point_local(ep: Episode, joint: str) -> tuple[int, np.ndarray]:
    """A point on the moving part, in the part body frame: the AABB centre pushed out far from a hinge."""
    drv = ep.driver
    j = drv.model.joint(joint)
    body = int(j.bodyid[0])
    name = drv.model.body(body).name
    lo, hi = drv.aabb(name)
    c = (lo + hi) / 2
    if drv.model.jnt_type[j.id] == 3:  # hinge: 80 % of the way from the axis to the far edge
        anchor = drv.data.xanchor[j.id]
        axis = drv.data.xaxis[j.id]
        corners = np.array([[x, y, c[2]] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])])
        rel = corners - anchor
        perp = rel - np.outer(rel @ axis, axis)
        far = corners[int(np.argmax(np.linalg.norm(perp, axis=1)))]
        c = anchor + (far - anchor) * 0.8
        c = c + axis * (np.dot((lo + hi) / 2 - anchor, axis) - np.dot(c - anchor, axis))
    r = drv.data.xmat[body].reshape(3, 3)
    return body, r.T @ (c - drv.data.xpos[body])


def static_box(ep: Episode, obj: str) -> tuple[np.ndarray, np.ndarray]:
    """World AABB of the object's carcass: its collision geoms that no hinge or slide moves."""

    drv = ep.driver
    m = drv.model
    root = drv.body_id(obj)
    moving = {int(m.jnt_bodyid[k]) for k in range(m.njnt) if m.jnt_type[k] in (HINGE, SLIDE)}

    def moves(b: int) -> bool:
        while b != root and b > 0:
            if b in moving:
                return True
            b = int(m.body_parentid[b])
        return False

    lo, hi = geom_world_aabbs(m, drv.data)
    sub = subtree_geoms(m, root)
    sel = [g for g in np.flatnonzero(sub) if not moves(int(m.geom_bodyid[g]))
           and (m.geom_contype[g] or m.geom_conaffinity[g])]
    if not sel:
        return drv.aabb(obj)
    return lo[sel].min(axis=0), hi[sel].max(axis=0)
