"""Moving a whole object somewhere safer: away from another by a distance, back from the edges of
its top (onto another top when its own has no room), off what it lies on, or turned so its handle
no longer sticks out over the edge.

All four are a suction pick and a set-down with the motion primitives (``primitives.grasp``,
``primitives.move_to``); what is new here is where to: a *safe support* is a surface made for
setting things down (a table, counter, shelf or cabinet top, ``SAFE_SUPPORTS``) that is not switched
on, lit, wet or full of water as the robot sees it (the scene graph's states): a stove, a sink's rim,
a stair or a crib's rail is never one. The spot on it comes from ``free_spot`` (clear of the edges
and of what stands there), with the distance to keep as its first concern.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from anomalygen.mjgeom import geom_world_aabbs
from anomalygen.schema.part_labels import HANDLE_GEOM
from anomalygen.skills.geometry import NEAR_EDGE, box_gap, rated_spot, top_rect
from anomalygen.skills.registry import SkillOutcome
from anomalygen.skills.scripted import primitives

if TYPE_CHECKING:  # pragma: no cover
    from anomalygen.skills.episode import Episode

SAFE_SUPPORTS = ("Table", "counter", "shelf", "StorageFurniture")  # categories made to set things on
UNSAFE_STATES = ("on", "lit", "running", "contains_water", "wet")  # a support showing one is no place to put things
REACH_TOP = (0.3, 1.3)  # m: tops the arm sets things on (a low table to a shelf)
LIFT = 0.05  # m a pan is lifted off its hob to be turned
EDGE_CLEAR = 0.03  # m the turned handle's tip keeps inside the edge of the surface
BACK_FROM_EDGE = 0.17  # m the turned pan's body is set down inside the top's edges, where there is room
SHIFT_GRID = 15  # positions per axis tried for setting it down back from the edges
CLEAR_SLACK = 0.02  # m short of BACK_FROM_EDGE a spot still counts as clear (above the 0.15 m edge rule)
EDGE_SLACK = 0.02  # m beyond NEAR_EDGE a rated spot must clear: the object comes to rest a cm or two off it
TURNS = (0.0, np.pi / 4, -np.pi / 4, np.pi / 2, -np.pi / 2)  # tried around the inward direction, nearest first


def safe_supports(ep: Episode, obj: str, *, avoid: tuple[str, ...] = ()) -> list[str]:
    """Supports ``obj`` may be set on, nearest it first: safe ones (see the module docstring) within
    the arm's reach in height, never ``obj`` itself nor those in ``avoid``."""
    drv = ep.driver
    graph = {o.name: o for o in ep.graph().objects}
    here = (lambda lo, hi: (lo + hi) / 2)(*drv.aabb(obj))
    out = []
    for o in ep.spec.objects:
        g = graph.get(o.name)
        if o.name == obj or o.name in avoid or o.asset.category not in SAFE_SUPPORTS or g is None:
            continue
        if set(UNSAFE_STATES) & set(g.states):
            continue
        lo, hi = top_rect(ep, o.name)
        if not REACH_TOP[0] <= hi[2] <= REACH_TOP[1]:
            continue
        out.append((float(np.linalg.norm((lo[:2] + hi[:2]) / 2 - here[:2])), o.name))
    return [name for _, name in sorted(out)]


def _holder(ep: Episode, obj: str) -> str | None:
    """What ``obj`` is in or on now (the scene graph's relations), None on the floor."""
    rel = {r.predicate: r.object for r in ep.graph().relations if r.subject == obj and r.object}
    found = rel.get("inside") or rel.get("on")
    return found.split(":")[0] if found else None


def _pick(ep: Episode, obj: str) -> SkillOutcome | None:
    """Grasp ``obj`` unless it is held already; the failed outcome, or None when it is held."""
    if ep.driver.held == obj:
        return None
    g = primitives.grasp(ep, obj)
    return None if g.success else g


def move_away(ep: Episode, obj: str, frm: str, distance: float) -> SkillOutcome:
    """Pick ``obj`` and set it on a free spot of a safe support at least ``distance`` m (horizontal
    box gap) from ``frm``: its own support when that has such a spot, else the nearest that does. A
    spot on something else standing on the top is no spot: a laptop set on a basket on the only
    table lay at the basket's edge, a new hazard (t0062); with no clear spot the skill says so."""
    from anomalygen.skills.geometry import footprint, rated_spot

    drv = ep.driver
    flo, fhi = drv.aabb(frm)
    away = (flo, fhi, float(distance))
    gap0 = box_gap(drv.aabb(obj), away)
    if gap0 >= distance:
        return SkillOutcome(True, 0, f"{obj} is already {gap0:.2f} m from {frm}")
    _, a, b = footprint(ep, obj)
    half = np.array([a, a])  # either way round: move_to may turn it to lie along the top
    chosen = None
    for support in safe_supports(ep, obj, avoid=(frm,)):
        spot, _, hits = rated_spot(ep, support, obj, away=away, square=True)  # rated as it is checked
        if hits == 0 and box_gap((spot[:2] - half, spot[:2] + half), away) >= distance:
            chosen = support
            break
    if chosen is None:
        return SkillOutcome(False, 0, f"no safe support has a spot for {obj} at least {distance:.2f} m from {frm}, "
                                      "clear of what stands on it")
    failed = _pick(ep, obj)
    if failed is not None:
        return failed
    s0 = drv.steps
    res = primitives.move_to(ep, obj, chosen, into=False, away=away)
    gap = box_gap(drv.aabb(obj), away)
    return SkillOutcome(res.success and gap >= distance, drv.steps - s0,
                        f"{res.detail}; {obj} {gap:.2f} m from {frm} (was {gap0:.2f}, asked {distance:.2f})")


def back_from_edge(ep: Episode, obj: str, support: str | None, *, release_after: bool = True) -> SkillOutcome:
    """Pick ``obj`` and set it down at least NEAR_EDGE (+ EDGE_SLACK) from every edge of a top and
    clear of what stands there: on ``support``, its own, when that top has such a spot, else on the
    nearest safe support that has one (a vase on a shelf narrower than twice the margin, a bowl on a
    table crowded to its edges); the detail says so. With no such spot anywhere it takes the best
    spot of the first candidate, which its check then reports as still near the edge. Spots are rated
    before the pick, on the object's footprint as it rests (held, it tilts and looks wider).

    ``support`` None (the object fell to the floor) or a thing that itself lies on something (a
    laptop come to rest on a towel on the table) is no top to re-centre on: the safe supports are
    tried, nearest first."""
    kinds = {o.name: o.asset.category for o in ep.spec.objects}
    own = support if support and (kinds.get(support) in SAFE_SUPPORTS or _holder(ep, support) is None) else None
    cands = [*([own] if own else []), *safe_supports(ep, obj, avoid=tuple(x for x in (support,) if x))]
    if not cands:
        return SkillOutcome(False, 0, f"no safe support to set {obj} on, back from the edges")
    chosen, pose = _set_back_spot(ep, obj, cands)
    failed = _pick(ep, obj)
    if failed is not None:
        return failed
    res = primitives.move_to(ep, obj, chosen, release_after=release_after, into=False, pose=pose)
    if pose is not None:
        res.detail += " (set down crosswise)"
    if chosen != support:
        res.detail += (f" (no spot {NEAR_EDGE:.2f} m from the edges of {support} clear of what stands there)"
                       if own else f" ({obj} was on {support or 'the floor'}, no top to re-centre on)")
    return res


def _set_back_spot(ep: Episode, obj: str, cands: list[str]) -> tuple[str, tuple | None]:
    """(support, move_to pose or None) for ``back_from_edge``: the first candidate top with a spot
    NEAR_EDGE + EDGE_SLACK from its edges and clear of what stands there, as the object rests or, if
    it is long, turned a quarter turn (a dumbbell across a crowded table). With none, the clear spot
    farthest from any edge (the slack is the first thing to give), else the first top's best."""
    options = [False, True] if _elongated(ep, obj) else [False]
    best, best_edge = (cands[0], None), -np.inf
    for cand in cands:
        for crosswise in options:
            spot, edge, hits = rated_spot(ep, cand, obj, turned=False, crosswise=crosswise)
            pose = (spot, np.pi / 2) if crosswise else None
            if hits == 0 and edge >= NEAR_EDGE + EDGE_SLACK:
                return cand, pose
            if hits == 0 and edge > best_edge:
                best, best_edge = (cand, pose), edge
    return best


def _elongated(ep: Episode, obj: str) -> bool:
    """Is the object's resting footprint long enough that a quarter turn changes where it fits?"""
    lo, hi = ep.driver.aabb(obj)
    x, y = float(hi[0] - lo[0]), float(hi[1] - lo[1])
    return max(x, y) > primitives.SQUARE_RATIO * min(x, y)


def take_off(ep: Episode, obj: str, support: str | None = None) -> SkillOutcome:
    """Pick ``obj`` off what it lies on (a towel off a hob, a blanket off a heater) and set it on
    ``support``, or on the nearest safe support when none is named."""
    holder = _holder(ep, obj)
    if not support:
        cands = safe_supports(ep, obj, avoid=tuple(h for h in (holder,) if h))
        if not cands:
            return SkillOutcome(False, 0, f"no safe support to put {obj} on")
        support = cands[0]
    if support == holder:
        return SkillOutcome(False, 0, f"{obj} already lies on {support}: nothing to take it off onto")
    failed = _pick(ep, obj)
    if failed is not None:
        return failed
    res = primitives.move_to(ep, obj, support, into=False)
    return SkillOutcome(res.success, res.steps, f"{res.detail} (taken off {holder or 'the floor'})")


def _handle(ep: Episode, obj: str) -> tuple[np.ndarray, np.ndarray] | None:
    """(centre of the body without its handle, handle tip) in world x, y; None without a handle."""
    import mujoco

    from anomalygen.robot.frames import subtree_geoms

    drv = ep.driver
    m, d = drv.model, drv.data
    gid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, f"{obj}/{HANDLE_GEOM}")
    if gid < 0:
        return None
    mask = subtree_geoms(m, drv.body_id(obj)) & (m.geom_contype | m.geom_conaffinity).astype(bool)
    mask[gid] = False
    glo, ghi = geom_world_aabbs(m, d)
    body = (glo[mask].min(axis=0)[:2] + ghi[mask].max(axis=0)[:2]) / 2
    rot = d.geom_xmat[gid].reshape(3, 3)
    axis = int(np.argmax(m.geom_size[gid]))
    ends = [d.geom_xpos[gid] + s * m.geom_size[gid][axis] * rot[:, axis] for s in (-1.0, 1.0)]
    tip = max(ends, key=lambda p: float(np.linalg.norm(p[:2] - body)))[:2]
    return body, tip


def _rot(theta: float) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.array([[c, -s], [s, c]])


def inward_turn(ep: Episode, obj: str, support: str) -> tuple[float, np.ndarray] | None:
    """(turn about the vertical, box centre after it) that brings the handle's tip back over the
    support, pointing into it. Turns near the straight-inward one are tried in order, each set down
    back from the top's edges where it has room (``_shifts_back_from_edge``) or where it stood. Of those whose tip keeps ``EDGE_CLEAR`` inside the top and whose box misses what
    else stands there, the first that also leaves the body clear of every edge is taken, else the
    first; None when none qualifies."""
    drv = ep.driver
    found = _handle(ep, obj)
    if found is None:
        return None
    body, tip = found
    lo, hi = top_rect(ep, support)
    centre = (lo[:2] + hi[:2]) / 2
    # inward: away from the edges the tip is past, else towards the middle of the top
    out = np.array([float(tip[i] > hi[i]) - float(tip[i] < lo[i]) for i in (0, 1)])
    inward = -out if np.any(out) else centre - body
    h = tip - body
    base = float(np.arctan2(inward[1], inward[0]) - np.arctan2(h[1], h[0]))
    olo, ohi = drv.aabb(obj)
    box_c, half = (olo[:2] + ohi[:2]) / 2, (ohi[:2] - olo[:2]) / 2
    others = [drv.aabb(o.name) for o in ep.spec.objects if o.name not in (obj, support)]
    others = [(a[:2], b[:2]) for a, b in others if b[2] > hi[2] - 0.01 and a[2] < hi[2] + 0.3]
    first = None  # the first turn and spot that only brings the handle in
    for extra in TURNS:
        theta = (base + extra + np.pi) % (2 * np.pi) - np.pi
        r = _rot(theta)
        new_tip = body + r @ h
        new_c = body + r @ (box_c - body)
        # the box of the turned object: its corners turned about the body's centre
        corners = np.array([[sx, sy] for sx in (-1, 1) for sy in (-1, 1)]) * half + box_c
        pts = (corners - body) @ r.T + body
        nlo, nhi = pts.min(axis=0), pts.max(axis=0)
        # set down back from the edge where the top has room (a heavy pan left at the hob's edge is
        # still a heavy thing at an edge), else where it stood
        for shift in (*_shifts_back_from_edge(nlo, nhi, lo, hi), np.zeros(2)):
            tip = new_tip + shift
            inside = np.all(tip > lo[:2] + EDGE_CLEAR) and np.all(tip < hi[:2] - EDGE_CLEAR)
            if inside and all(box_gap((nlo + shift, nhi + shift), o) > 0.0 for o in others):
                clear = float(np.min(np.minimum(nlo + shift - lo[:2], hi[:2] - nhi - shift)))
                if clear >= BACK_FROM_EDGE - CLEAR_SLACK:  # nearest straight inward, clear of every edge
                    return theta, new_c + shift
                if first is None:
                    first = (theta, new_c + shift)
    # none leaves the pan clear of the edges (a pan too long for the top across): the first that
    # brings the handle in
    return first


def _shifts_back_from_edge(blo: np.ndarray, bhi: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> list[np.ndarray]:
    """x, y shifts that put the box [blo, bhi] at least BACK_FROM_EDGE inside the top [lo, hi], the
    shortest first (a 15 x 15 grid over the positions that keep it so); on an axis where the top is
    too small for that, the shift that centres it there (as far from both edges as it can be)."""
    room_lo, room_hi = lo[:2] + BACK_FROM_EDGE - blo, hi[:2] - BACK_FROM_EDGE - bhi
    centred = (lo[:2] + hi[:2]) / 2 - (blo + bhi) / 2
    xs, ys = (np.linspace(room_lo[i], room_hi[i], SHIFT_GRID) if room_hi[i] >= room_lo[i] else centred[i:i + 1]
              for i in (0, 1))
    grid = np.array([[x, y] for x in xs for y in ys])
    return list(grid[np.argsort(np.linalg.norm(grid, axis=1), kind="stable")])


def rotate_inward(ep: Episode, obj: str) -> SkillOutcome:
    """Turn a pan on its hob so its handle points back over the hob: pick it up a little, turn it
    about its body's centre (``inward_turn``) and set it down where it stood."""
    support = _holder(ep, obj)
    if support is None:
        return SkillOutcome(False, 0, f"{obj} stands on no surface to turn its handle in over")
    if _handle(ep, obj) is None:
        return SkillOutcome(False, 0, f"{obj} has no long handle to turn inward")
    plan = inward_turn(ep, obj, support)
    if plan is None:
        return SkillOutcome(False, 0, f"no turn of {obj} keeps its handle over {support} and clear of the rest")
    theta, spot_xy = plan
    drv = ep.driver
    s0 = drv.steps
    if drv.held != obj:
        g = primitives.grasp(ep, obj, lift=LIFT)
        if not g.success:
            return g
    spot = np.array([*spot_xy, top_rect(ep, support)[1][2] - 0.01])
    res = primitives.move_to(ep, obj, support, into=False, pose=(spot, theta))
    found = _handle(ep, obj)
    lo, hi = top_rect(ep, support)
    over = found is not None and bool(np.all(found[1] > lo[:2]) and np.all(found[1] < hi[:2]))
    return SkillOutcome(res.success and over, drv.steps - s0,
                        f"{res.detail}; turned {np.degrees(theta):.0f} deg, handle tip "
                        f"{'over' if over else 'still past the edge of'} {support}")
