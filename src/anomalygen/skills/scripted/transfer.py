"""``take_out_of``: lift an object out of a container or an appliance and keep holding it.

Two ways in, by what the robot has opened:
- a compartment behind a door (a microwave, a cabinet shelf) that ``parts.open_for_access`` opened
  and recorded in the episode's ``memory.compartments``: the cup comes in level through the opening just above the
  object, closes in on it until suction catches, lifts it a little, backs out the way it came and
  rises (``place_through_door`` run backwards). Face-down, the wrist stands 0.2 m above the cup,
  more than a microwave's ceiling leaves; so when the cup is stopped at the opening it backs out and
  comes again with its axis tilted 30, then 45 degrees towards the inside, the wrist trailing out
  of the opening. An object deep inside stays out of reach: the forearm meets the opening's top edge.
- anything open at the top (a box with its lid up, a basket): a plain grasp, then a lift until the
  object's bottom clears the rim.
The object stays held, so the next step (``place_on``, ``place_inside``) decides where it goes.
"""

from __future__ import annotations

import numpy as np

from anomalygen.schema import DOOR
from anomalygen.skills.episode import Episode
from anomalygen.skills.geometry import PRE_CONTACT, grasp_points, rim_z
from anomalygen.skills.registry import SkillOutcome
from anomalygen.skills.scripted.primitives import grasp

BACK_OUT_CLEAR = 0.1  # m the cup backs out beyond the container's box with the object
IN_FRONT = 0.2  # m in front of the opening where the cup lines up before going in
INSIDE_LIFT = 0.02  # m the object is lifted inside a compartment (its ceiling is close)
RIM_CLEAR = 0.05  # m the object's bottom rises above an open-topped container's rim
# cup axis from straight down, tried in turn; no more than 45 degrees: a bellows cup tilted further
# off the object's face would not seal on it (the simulated suction checks only the distance)
TILTS = (0.0, np.radians(30), np.radians(45))
DOOR_STOP_MARGIN = 0.05  # rad short of the door's stop
DOOR_WIDE_TOL = 0.15  # rad: a door this near its stop is left as it is
HINGE = 3  # mujoco.mjtJoint.mjJNT_HINGE
REACHED_TOL = 0.03  # m: a cup further than this from the pre-contact point was stopped on the way in


def take_out_of(ep: Episode, obj: str, container: str) -> SkillOutcome:
    """Take ``obj`` out of ``container``; True when it is held and clear of it."""
    from anomalygen.robot.ik import quat_z_to

    drv = ep.driver
    s0 = drv.steps
    if drv.held == obj:  # a retry: it was grasped but is not out yet
        if container in ep.memory.compartments:
            out = ep.memory.compartments[container][2]
            _back_out(ep, _outside(ep, container, out, int(np.argmax(np.abs(out[:2])))))
        return SkillOutcome(True, drv.steps - s0, f"already holding {obj}; moved it clear of {container}")
    if container not in ep.memory.compartments:
        g = grasp(ep, obj, lift=0.12)
        if not g.success:
            return g
        olo = drv.aabb(obj)[0]
        rise = max(0.0, rim_z(ep, container) + RIM_CLEAR - olo[2])
        if rise > 0:
            drv.goto(drv.site + np.array([0, 0, rise]), max_steps=150)
        return SkillOutcome(drv.held == obj, drv.steps - s0, f"{obj} lifted out of {container} from the top")
    _swing_door_wide(ep, container)
    lo, hi, out = ep.memory.compartments[container]
    k = int(np.argmax(np.abs(out[:2])))
    mouth = hi[k] if out[k] > 0 else lo[k]  # the opening's plane along the outward axis
    n = np.array([0.0, 0.0, 1.0])
    d = drv.data
    tried = []
    centre = (lo + hi) / 2
    centre[k] = mouth + out[k] * IN_FRONT  # in front of the middle of the opening
    for tilt in TILTS:
        for point in grasp_points(ep, obj):
            # Come in from the middle of the opening towards the object, so the trailing wrist stays
            # clear of the side walls and the open door. The cup's axis points that way and down;
            # tilted, the wrist trails out of the opening instead of standing 0.2 m above the cup.
            h = np.array([*(point[:2] - centre[:2]), 0.0])
            h = h / (np.linalg.norm(h) + 1e-9)
            v = h * np.sin(tilt) - n * np.cos(tilt)
            quat = quat_z_to(v)
            pre = point - v * PRE_CONTACT
            front = pre - h * (abs(mouth - pre[k]) / max(abs(h[k]), 0.5) + IN_FRONT)
            if not drv.place_base_near(front, side=-h, reach_poses=[(front, quat), (pre, quat)]):
                continue
            drv.goto(np.array([*drv.site[:2], max(drv.site[2], pre[2])]), max_steps=150)
            drv.goto(np.array([*front[:2], drv.site[2]]), max_steps=200)
            drv.goto(front, quat, max_steps=150)
            drv.goto(pre, quat, max_steps=200, tol=0.015)
            short = float(np.linalg.norm(drv.site - pre))  # stopped on the way in by the opening's edges
            for j in range(40):  # close in along the cup's axis, 2.5 mm a waypoint, until suction catches
                drv.goto(point - v * (PRE_CONTACT - 0.0025 * j), quat, max_steps=12, tol=0.004)
                if drv.agent.cup_distance(d, obj) < drv.agent.SUCTION_RANGE * 0.8 and drv.agent.grab(d, obj):
                    break
            if drv.held == obj:  # straight out along the opening's normal (back along h can clip the side)
                _back_out(ep, _outside(ep, container, out, k))
                return SkillOutcome(drv.held == obj, drv.steps - s0,
                                       f"{obj} taken out of {container} through its opening (cup tilted {np.degrees(tilt):.0f} deg)")
            tried.append(f"{np.degrees(tilt):.0f} deg: stopped {short:.2f} m short, suction did not catch")
            drv.goto(front, quat, max_steps=200, tol=0.02)
            if short > REACHED_TOL:  # blocked at the opening: the next grasp point will not do better, tilt more
                break
    return SkillOutcome(False, drv.steps - s0, f"{obj} not taken out of {container}: " + "; ".join(tried or ["no base pose"]))


def _swing_door_wide(ep: Episode, container: str) -> None:
    """Open the hinged door(s) the access step opened to their stop. Opened part way (about 90
    degrees) a side door stands square to the opening, where the arm reaching in meets it and
    pushes it shut again; at its stop it is folded back, out of the way."""
    from anomalygen.skills.scripted.access import closure_joints
    from anomalygen.skills.scripted.parts import actuate_part

    drv = ep.driver
    for js in closure_joints(ep, container, (DOOR,)):
        if js.name not in ep.memory.opened.get(container, []) or drv.model.joint(js.name).type[0] != HINGE:
            continue
        lo, hi = js.range
        far = hi if abs(hi - js.closed_value) >= abs(lo - js.closed_value) else lo
        goal = far - np.sign(far - js.closed_value) * DOOR_STOP_MARGIN
        if abs(float(drv.data.joint(js.name).qpos[0]) - goal) > DOOR_WIDE_TOL:
            actuate_part(ep, js.name, goal, closed=js.closed_value, tol=DOOR_WIDE_TOL)


def _outside(ep: Episode, container: str, out: np.ndarray, k: int) -> np.ndarray:
    """A cup point straight out from where it is, past the container's whole box (an open door
    folded back reaches out beside the opening; until the object is past it, it counts as inside)."""
    drv = ep.driver
    clo, chi = drv.aabb(container)
    face = chi[k] if out[k] > 0 else clo[k]
    return drv.site + out * (abs(face - drv.site[k]) + BACK_OUT_CLEAR)


def _back_out(ep: Episode, front: np.ndarray) -> None:
    """Lift the held object a little, back out level to the point in front of the opening, rise."""
    drv = ep.driver
    n = np.array([0.0, 0.0, 1.0])
    quat = drv.data.mocap_quat[drv._mocap].copy()
    up = drv.site + n * INSIDE_LIFT
    drv.goto(up, quat, max_steps=40)
    drv.goto(np.array([front[0], front[1], up[2]]), quat, max_steps=200, tol=0.02)
    drv.goto(drv.site + n * 0.12, quat, max_steps=100)
