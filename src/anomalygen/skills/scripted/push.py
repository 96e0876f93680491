"""``push_to``: move a free object over the floor until it stands beside a piece of furniture.

Why not a side push: the base is placed kinematically between motions (it does not drive while the
arm is in contact), and a push from the side with a single suction cup turns and topples anything
that is not a low, wide block. So the object is held by suction on its top, kept a few centimetres
above the floor, carried along with the base to a free spot of floor beside the furniture, lowered
until it touches and let go. Heavy things never rise higher than that, so nothing is dropped from
height and the path stays at floor level, as a push would.

The spot is chosen from the scene the robot perceives (the scene spec and the simulated geometry
read through the Driver): along the four sides of the furniture's footprint, a small gap away, where
the object's footprint overlaps nothing standing on the floor, lies inside the room and has bare
floor under every corner (not a wall or a rug edge), nearest the object's present place.
"""

from __future__ import annotations

import numpy as np

from anomalygen.skills.episode import Episode
from anomalygen.skills.geometry import floor_below, static_box
from anomalygen.skills.registry import SkillOutcome
from anomalygen.skills.scripted.primitives import grasp, release
from anomalygen.skills.scripted.setdown import lower_until_contact
from anomalygen.world.room import ROOM_CENTER, ROOM_HALF

SIDE_GAP = 0.08  # m between the furniture's footprint and the object (well under the walkway's 0.3 m)
CLEARANCE = 0.025  # m the object's bottom is kept above the floor while it is moved
KEEP_OFF = 0.04  # m kept from other things' footprints at the chosen spot
ROOM_MARGIN = 0.15  # m the object stays inside the furnished floor area (world/room.py ROOM_HALF)
FLOOR_TOL = 0.02  # m: a ray that hits lower than this hit the floor itself
SPOTS_PER_SIDE = 9


def floor_spot_beside(ep: Episode, obj: str, anchor: str) -> np.ndarray | None:
    """Centre (x, y) of a free floor spot for ``obj`` beside ``anchor``, or None when there is none."""

    drv = ep.driver
    alo, ahi = static_box(ep, anchor)
    olo, ohi = drv.aabb(obj)
    half = (ohi[:2] - olo[:2]) / 2
    here = (olo[:2] + ohi[:2]) / 2
    others = []
    for o in ep.spec.objects:
        if o.name in (obj, anchor):
            continue
        blo, bhi = drv.aabb(o.name)
        if blo[2] < ohi[2] - olo[2] + 0.05:  # stands low enough to be in the object's way
            others.append((blo[:2] - KEEP_OFF, bhi[:2] + KEEP_OFF))
    room_lo = np.asarray(ROOM_CENTER)[:2] - np.asarray(ROOM_HALF) + ROOM_MARGIN
    room_hi = np.asarray(ROOM_CENTER)[:2] + np.asarray(ROOM_HALF) - ROOM_MARGIN
    cands = []
    for k in (0, 1):  # sides normal to x, then to y
        j = 1 - k
        for sign, edge in ((-1.0, alo[k]), (1.0, ahi[k])):
            c_k = edge + sign * (SIDE_GAP + half[k])
            span = np.linspace(alo[j] + half[j], ahi[j] - half[j], SPOTS_PER_SIDE) if ahi[j] - alo[j] > 2 * half[j] \
                else [float((alo[j] + ahi[j]) / 2)]
            for c_j in span:
                p = np.zeros(2)
                p[k], p[j] = c_k, c_j
                cands.append(p)
    cands.sort(key=lambda p: float(np.linalg.norm(p - here)))
    for p in cands:
        if np.any(p - half < room_lo) or np.any(p + half > room_hi):
            continue
        if any(np.all(p + half > a) and np.all(p - half < b) for a, b in others):
            continue
        if all(_bare_floor(ep, obj, p + half * np.array(c)) for c in ((0, 0), (1, 1), (1, -1), (-1, 1), (-1, -1))):
            return p
    return None


def _bare_floor(ep: Episode, obj: str, xy: np.ndarray) -> bool:
    z = floor_below(ep, np.array([xy[0], xy[1], 2.5]), obj)
    return z is not None and z < FLOOR_TOL


def _steady(ep: Episode, obj: str, max_steps: int = 40) -> None:
    """Wait for the held object to stop swinging (set down while swinging it lands off the spot)."""
    drv = ep.driver
    b = drv.body_id(obj)
    for _ in range(max_steps):
        if np.linalg.norm(drv.data.cvel[b][:3]) < 0.15 and np.linalg.norm(drv.data.cvel[b][3:]) < 0.02:
            return
        drv.step()


def push_to(ep: Episode, obj: str, anchor: str) -> SkillOutcome:
    """Move ``obj`` over the floor to a free spot beside ``anchor`` and let go there."""
    from anomalygen.robot.ik import quat_z_to

    drv = ep.driver
    s0 = drv.steps
    goal = floor_spot_beside(ep, obj, anchor)
    if goal is None:
        return SkillOutcome(False, 0, f"no free floor beside {anchor} for {obj}")
    if drv.held != obj:
        g = grasp(ep, obj, lift=CLEARANCE)
        if not g.success:
            return SkillOutcome(False, drv.steps - s0, g.detail)
    quat = quat_z_to(np.array([0.0, 0.0, -1.0])) if drv.cup_down(0.7) else drv.data.mocap_quat[drv._mocap].copy()
    olo, ohi = drv.aabb(obj)
    below = drv.site[2] - olo[2]  # cup face to the object's bottom
    off = (olo[:2] + ohi[:2]) / 2 - drv.site[:2]  # the object's centre from the cup, seen from above
    carry = np.array([*(goal - off), below + CLEARANCE])
    low = np.array([*(goal - off), below])
    if not drv.place_base_near(carry, reach_poses=[(carry, quat), (low, quat)]):
        release(ep)
        return SkillOutcome(False, drv.steps - s0, f"no collision-free base pose beside {anchor}")
    if not drv.reach_planned((carry,), quat):
        drv.goto(carry, quat, max_steps=250)
    _steady(ep, obj)
    for _ in range(2):  # the base pose only approximates the spot: correct what is left
        olo, ohi = drv.aabb(obj)
        err = goal - (olo[:2] + ohi[:2]) / 2
        if np.linalg.norm(err) < 0.01:
            break
        carry[:2] += err
        low[:2] += err
        drv.goto(carry, quat, max_steps=120, tol=0.01)
        _steady(ep, obj)
    ok = lower_until_contact(ep, obj, low, quat)
    release(ep)
    drv.goto(drv.site + np.array([0, 0, 0.15]), quat, max_steps=80)
    olo, ohi = drv.aabb(obj)
    miss = float(np.linalg.norm(goal - (olo[:2] + ohi[:2]) / 2))
    return SkillOutcome(ok, drv.steps - s0, f"{obj} set down beside {anchor}, {miss:.2f} m from the chosen spot")
