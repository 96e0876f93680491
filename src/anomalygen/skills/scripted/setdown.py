"""Setting a held object down: wait for its swing to die, centre it over a spot, lower it until it
touches something (a guarded move), and the contact test that move uses."""

from __future__ import annotations

import numpy as np

from anomalygen.robot.frames import subtree_geoms
from anomalygen.skills.episode import Episode


def let_swing_die(ep: Episode, obj: str, max_steps: int = 40) -> None:
    """Hold still until the carried object stops swinging: set down while swinging, it lands tilted."""
    drv = ep.driver
    b = drv.body_id(obj)
    for _ in range(max_steps):
        w, v = drv.data.cvel[b][:3], drv.data.cvel[b][3:]
        if np.linalg.norm(w) < 0.15 and np.linalg.norm(v) < 0.02:
            return
        drv.step()


TURNED_TOL = np.radians(10)  # rad the cup's axis may stay off the direction it was sent to
TURN_MAX_STEPS = 200  # control steps to wait for the cup to turn there


def turn_until_there(ep: Episode, quat, *, tol: float = TURNED_TOL, max_steps: int = TURN_MAX_STEPS) -> bool:
    """Hold the target until the cup's axis points the way ``quat`` has it. ``goto`` stops once the
    cup is in place, and a big turn on the spot (a held bottle tipped to lie ahead of the cup) lags
    behind: carried on still half upright, a bleach bottle went in askew and stuck in the door."""
    import mujoco

    drv = ep.driver
    r = np.zeros(9)
    mujoco.mju_quat2Mat(r, np.asarray(quat, dtype=float) / np.linalg.norm(quat))
    want = r.reshape(3, 3)[:, 2]
    for _ in range(max_steps):
        if float(drv.data.xmat[drv._cup].reshape(3, 3)[:, 2] @ want) > np.cos(tol):
            return True
        drv.step()
    return False


def lower_until_contact(ep: Episode, obj: str, target, quat, *, max_steps: int = 300, tol: float = 0.02) -> bool:
    """Lower the held object towards ``target`` (cup face) and stop the moment it touches anything.

    A guarded move: the weld is stiff, so pressing on would push a needle through a thin bottom. It
    also stops where the arm can reach no lower with the cup upright (deep in a box on the floor the
    wrist tilts and the swinging object knocks the lid shut). True when the target was reached or
    the object came to rest on something."""
    drv = ep.driver
    target = np.asarray(target, dtype=float)
    upright = drv.cup_down(0.9)
    touched = arm_touches(ep, obj)  # what the arm already leans on is no reason to stop
    dp = drv.dp
    try:
        for _ in range(max_steps):
            if held_touches(ep, obj) or arm_touches(ep, obj) - touched:
                return True  # the object is down, or the arm reached a rim (pressing on shoves the bin)
            if upright and not drv.cup_down(0.9):  # as low as the arm goes with the cup upright: let go
                return True
            # the last 8 cm slowly (3 mm a step): at full speed a 4 mm bottom is crossed between checks
            drv.dp = SLOW_DP if drv.site[2] - target[2] < 0.08 else dp
            drv.goto(target, quat, max_steps=1, tol=0.0)
            if np.linalg.norm(drv.site - target) < tol:
                return True
        return False
    finally:
        drv.dp = dp


SLOW_DP = 0.003  # m per control step for the final part of a set-down


def held_touches(ep: Episode, obj: str) -> bool:
    """Does the held object touch something other than the robot?"""

    drv = ep.driver
    d = drv.data
    mask = subtree_geoms(drv.model, drv.body_id(obj))
    for i in range(d.ncon):
        g1, g2 = int(d.contact.geom1[i]), int(d.contact.geom2[i])
        if mask[g1] == mask[g2]:
            continue
        other = g2 if mask[g1] else g1
        if other not in drv._robot_geoms and d.contact.dist[i] < 0.0005:
            return True
    return False


def centre_over(ep: Episode, obj: str, aim, above, low, quat):
    """Move the cup so the held object's centre is over ``aim`` (x, y) at ``above``'s height, twice at
    most (the base pose only approximates it; a swing or a turn of the wrist shifts it): returns
    ``above`` and ``low`` shifted alike."""
    drv = ep.driver
    for _ in range(2):
        olo, ohi = drv.aabb(obj)
        err = np.asarray(aim)[:2] - (olo[:2] + ohi[:2]) / 2
        if np.linalg.norm(err) < 0.01:
            break
        above = np.array([above[0] + err[0], above[1] + err[1], above[2]])
        low = np.array([low[0] + err[0], low[1] + err[1], low[2]])
        drv.goto(above, quat, max_steps=120, tol=0.01)
        let_swing_die(ep, obj)
    return above, low


def arm_touches(ep: Episode, obj: str) -> set[int]:
    """Bodies other than the floor and the held object that the robot touches."""
    drv = ep.driver
    m, d = drv.model, drv.data
    held = drv.body_id(obj)
    out = set()
    for i in range(d.ncon):
        g1, g2 = int(d.contact.geom1[i]), int(d.contact.geom2[i])
        if (g1 in drv._robot_geoms) == (g2 in drv._robot_geoms) or drv._floor in (g1, g2):
            continue
        b = int(m.body_rootid[m.geom_bodyid[g2 if g1 in drv._robot_geoms else g1]])
        if b != held and d.contact.dist[i] < 0.0:
            out.add(b)
    return out
