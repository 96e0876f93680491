"""``take_out_of``: lift an object out of a container or an appliance and keep holding it.

Two ways in, by what the robot has opened:
- a compartment behind a door (a microwave, a cabinet shelf) that ``parts.open_for_access`` opened
  and recorded in ``drv.compartments``: the cup, face-down, comes in level through the opening just
  above the object, descends onto it until suction catches, lifts it a little, backs out the way it
  came and rises. It is ``place_through_door`` run backwards;
- anything open at the top (a box with its lid up, a basket): a plain grasp, then a lift until the
  object's bottom clears the rim.
The object stays held, so the next step (``place_on``, ``place_inside``) decides where it goes.
"""

from __future__ import annotations

import numpy as np

from anomalygen.control.driver import PRE_CONTACT, Driver, PrimitiveResult
from anomalygen.control.geometry import grasp_points, rim_z
from anomalygen.control.primitives import grasp

IN_FRONT = 0.2  # m in front of the opening where the cup lines up before going in
INSIDE_LIFT = 0.02  # m the object is lifted inside a compartment (its ceiling is close)
RIM_CLEAR = 0.05  # m the object's bottom rises above an open-topped container's rim


def take_out_of(drv: Driver, obj: str, container: str) -> PrimitiveResult:
    """Take ``obj`` out of ``container``; True when it is held and clear of it."""
    from anomalygen.control.ik import quat_z_to
    from anomalygen.scene import robot

    s0 = drv.steps
    if drv.held == obj:
        return PrimitiveResult(True, 0, f"already holding {obj}")
    if container not in drv.compartments:
        g = grasp(drv, obj, lift=0.12)
        if not g.success:
            return g
        olo = drv.aabb(obj)[0]
        rise = max(0.0, rim_z(drv, container) + RIM_CLEAR - olo[2])
        if rise > 0:
            drv.goto(drv.site + np.array([0, 0, rise]), max_steps=150)
        return PrimitiveResult(drv.held == obj, drv.steps - s0, f"{obj} lifted out of {container} from the top")
    lo, hi, out = drv.compartments[container]
    k = int(np.argmax(np.abs(out[:2])))
    mouth = hi[k] if out[k] > 0 else lo[k]  # the opening's plane along the outward axis
    quat = quat_z_to(np.array([0.0, 0.0, -1.0]))
    n = np.array([0.0, 0.0, 1.0])
    m, d = drv.model, drv.data
    for point in grasp_points(drv, obj):
        pre = point + n * PRE_CONTACT
        front = pre + out * (abs(mouth - pre[k]) + IN_FRONT)
        if not drv.place_base_near(front, side=out, reach_poses=[(front, quat), (pre, quat)]):
            return PrimitiveResult(False, drv.steps - s0, f"no base pose in front of {container}'s opening")
        drv.goto(np.array([*drv.site[:2], max(drv.site[2], pre[2])]), quat, max_steps=150)
        drv.goto(np.array([*front[:2], drv.site[2]]), quat, max_steps=200)
        drv.goto(front, quat, max_steps=150)
        drv.goto(pre, quat, max_steps=200, tol=0.015)
        grabbed = False
        for j in range(40):  # descend 2.5 mm a waypoint until suction catches
            drv.goto(point + n * (PRE_CONTACT - 0.0025 * j), quat, max_steps=12, tol=0.004)
            if robot.object_distance_to_cup(m, d, obj) < robot.SUCTION_RANGE * 0.8 and robot.suction_on(m, d, obj):
                grabbed = True
                break
        up = drv.site + n * INSIDE_LIFT
        drv.goto(up, quat, max_steps=40)
        drv.goto(np.array([front[0], front[1], up[2]]), quat, max_steps=200, tol=0.02)  # back out level
        drv.goto(drv.site + n * 0.12, quat, max_steps=100)
        if grabbed and drv.held == obj:
            return PrimitiveResult(True, drv.steps - s0, f"{obj} taken out of {container} through its opening")
    return PrimitiveResult(False, drv.steps - s0, f"suction did not catch {obj} inside {container}")
