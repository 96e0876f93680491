"""Lay a held object on its side before it goes through a low, shallow door, or into a lidded box
it would stand out of.

Put through a low door (a floor safe) the object goes in ahead of a horizontal cup: held by its top
and tipped 90 degrees, its height then runs into the compartment. A spray bottle 0.23 m tall does
not fit a safe 0.16 m deep that way (it stood out of the door, and the door shoved it out on
closing), though lying on its side it fits easily. So when the held object is taller than the
compartment is deep it is first laid on its side on the floor in front of the opening and taken
again by its new top: its long side then runs across the opening and only its thickness goes in.

The same holds for a box that shuts with a lid on top: a watering can 0.2 m tall stood in a storage
box 0.17 m deep, and the lid, shut on it, shoved it back out. Tipped along its short side it lies
0.16 m high and the lid shuts over it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from anomalygen.robot.frames import subtree_geoms
from anomalygen.skills.episode import Episode
from anomalygen.skills.geometry import HINGE, floor_below, footprint, static_box

DEPTH_MARGIN = 0.02  # m the object's extent along the cup must stay short of the compartment's depth
LAY_DOWN_OUT = 0.35  # m in front of the opening where the object is laid down
LAY_DOWN_HIGH = 0.25  # m over the floor where the object is tipped over, clear of everything
LYING_TOL = np.radians(25)  # rad the cup's axis may stay off horizontal: the object still falls on its side
LYING_TURN = np.radians(45)  # rad an object laid down must have turned over by, else it landed upright
# (by turn, not height: a watering can 0.2 m tall lies 0.16 m high)


def depth_inside(ep: Episode, lo: np.ndarray, hi: np.ndarray, out: np.ndarray, obj: str) -> float:
    """How deep the compartment is, mouth to back wall, along its middle (a ray in through the
    opening; the measured box runs to the carcass's outside and counts the back wall in)."""
    import mujoco

    drv = ep.driver
    m, d = drv.model, drv.data
    k = int(np.argmax(np.abs(out[:2])))
    mouth = hi[k] if out[k] > 0 else lo[k]
    start = (lo + hi) / 2
    start[k] = mouth + out[k] * 0.05
    skip = subtree_geoms(m, drv.body_id(obj)) | np.isin(np.arange(m.ngeom), list(drv._robot_geoms))
    geomid = np.zeros(1, dtype=np.int32)
    travelled = 0.0
    for _ in range(6):  # step past the held object and the arm
        dist = mujoco.mj_ray(m, d, start, -out, None, 1, -1, geomid)
        if dist < 0:
            break
        travelled += dist
        if not skip[int(geomid[0])]:
            return max(0.0, travelled - 0.05)
        start = start - out * (dist + 1e-4)
        travelled += 1e-4
    return float(abs(hi[k] - lo[k]))


def too_tall_to_go_in(ep: Episode, obj: str, depth: float) -> bool:
    """Would the held object, tipped ahead of a horizontal cup, stick out of a compartment this deep?"""
    drv = ep.driver
    return drv.site[2] - drv.aabb(obj)[0][2] + DEPTH_MARGIN > depth


LID_HEADROOM = 0.01  # m the object must stay under the rim of a box whose lid shuts on top


def tip_direction_for_lid(ep: Episode, obj: str, region: str) -> np.ndarray | None:
    """The horizontal direction (the held object's short side, towards the robot) to lay it down along
    when, standing as it hangs, it would stand above the rim of ``region`` whose opened lid is to shut
    on top, while on its side it fits under; None when it goes in as it is (or lying does not help)."""
    drv = ep.driver
    m = drv.model
    if not any(m.jnt_type[m.joint(j).id] == HINGE for j in ep.memory.opened.get(region, [])):
        return None
    lo, hi = static_box(ep, region)
    centre = (lo + hi) / 2
    floor = floor_below(ep, np.array([centre[0], centre[1], hi[2] + 0.04]), obj)
    if floor is None:
        return None
    depth = float(hi[2]) - floor
    olo, ohi = drv.aabb(obj)
    yaw, _, half_width = footprint(ep, obj)
    if ohi[2] - olo[2] + LID_HEADROOM <= depth or 2 * half_width + LID_HEADROOM > depth:
        return None
    short = np.array([-np.sin(yaw), np.cos(yaw), 0.0])
    base = drv.agent.base_pose(drv.data)[:2]
    return short if float(np.dot(base - centre[:2], short[:2])) >= 0 else -short


def beside(ep: Episode, region: str, out: np.ndarray) -> np.ndarray:
    """A floor spot ``LAY_DOWN_OUT`` beyond ``region``'s side that faces ``out``."""
    lo, hi = static_box(ep, region)
    centre = (lo + hi) / 2
    half = 0.5 * float(abs(out[0]) * (hi[0] - lo[0]) + abs(out[1]) * (hi[1] - lo[1]))
    return centre + out * (half + LAY_DOWN_OUT)


def lay_on_side(ep: Episode, obj: str, spot: np.ndarray, out: np.ndarray, take_again: Callable[[], bool]) -> bool:
    """Tip the held object over (its top towards ``-out``) at ``spot`` on the floor, set it down
    there lying on its side, let go and take it again from above (``take_again``, the grasp primitive). True when it is held again and
    did lie down (lowered a long way, the arm can turn the cup back down and the object lands upright)."""
    import mujoco

    from anomalygen.robot.ik import quat_z_to
    from anomalygen.skills.scripted.setdown import let_swing_die, lower_until_contact, turn_until_there

    drv = ep.driver
    up = drv.data.xmat[drv.body_id(obj)].reshape(3, 3)[:, 2].copy()  # the object's own up, as held
    down = quat_z_to(np.array([0.0, 0.0, -1.0]))
    floor = floor_below(ep, np.array([spot[0], spot[1], spot[2] + 1.0]), obj)
    floor = 0.0 if floor is None else floor
    high = np.array([spot[0], spot[1], max(drv.site[2], floor + LAY_DOWN_HIGH + drv.site[2] - drv.aabb(obj)[0][2])])
    drv.goto(np.array([*drv.site[:2], high[2]]), down, max_steps=150)
    axis = np.cross(np.array([0.0, 0.0, 1.0]), out)
    side = np.zeros(4)
    mujoco.mju_mulQuat(side, np.array([np.cos(np.pi / 4), *(np.sin(np.pi / 4) * axis)]), down)
    if not drv.place_base_near(high, side=out, reach_poses=[(high, down), (high, side)]):
        return False
    drv.goto(high, down, max_steps=200)
    for f in np.linspace(0.25, 1.0, 4):
        q = np.zeros(4)
        mujoco.mju_mulQuat(q, np.array([np.cos(f * np.pi / 4), *(np.sin(f * np.pi / 4) * axis)]), down)
        drv.goto(high, q, max_steps=40)
    turn_until_there(ep, side, tol=LYING_TOL)
    let_swing_die(ep, obj)
    below = drv.site[2] - drv.aabb(obj)[0][2]
    lower_until_contact(ep, obj, np.array([*drv.site[:2], floor + below - 0.03]), side)
    drv.agent.release(drv.data)
    drv.settle(15)
    drv.goto(drv.site + out * 0.08, side, max_steps=40)
    drv.goto(drv.site + np.array([0.0, 0.0, 0.2]), side, max_steps=100)
    drv.straighten_wrist()
    lying = float(np.dot(up, drv.data.xmat[drv.body_id(obj)].reshape(3, 3)[:, 2])) < np.cos(LYING_TURN)
    return take_again() and lying
