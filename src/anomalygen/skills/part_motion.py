"""Moving a part held by suction, for the switch-off family: grasp a knob or switch, read it, lead it, let go.

Below both kinds of skill: the scripted primitive (:mod:`~anomalygen.skills.scripted.controls`, the
family's reference paced) and the learned skill (:mod:`~anomalygen.skills.learned.part_subtask`, its
env :mod:`~anomalygen.skills.learned.part_env`, a policy) hold, read, lead and let go of a part through
this module, so neither imports the other for it (``tests/test_layout.py``).

Why a family-level observation: appliances differ (an oven has 2-5 front knobs turning about a
horizontal axis, a toaster one side knob, a coffee machine a push button on top, a kettle a switch
under its handle), and so do their sizes, knob radii and where the scene builder puts them. A policy
that reads world coordinates or raw joint values learns one scene. :class:`PartReadout` reads only
quantities relative to the cup and the part, so the shipped warm start
(``anomalygen/data/policies/switch_off.zip``) transfers across built scenes:

- the grasped point (where suction took hold) minus the cup body's origin (where the weld anchors
  it), in dm: how far the hold is stretched;
- the direction in which the grasped point moves when the joint goes *towards off* (a knob's tangent
  at the grasped point, a button's axis), a unit vector;
- the lever: grasped point minus the joint axis, perpendicular to the axis, in dm (0 for a slide);
  following a tangent alone drifts off a circle of 1-2 cm, the lever says where the centre is;
- how far the part still is from off (fraction of its travel, 1 = fully on, 0 = off) and its sign;
- the suction flag and the time fraction.

17 numbers whatever the appliance. The reward is the sub-task's RewardSpec (knob angle towards off,
scaled by the joint's travel, and the cup near the part), evaluated on the same state dict as every
SAC sub-task (:mod:`~anomalygen.skills.learned.reward`).

Pre-positioning (:func:`grasp_part`): the 7-D action cannot move the base, and suction holds a part
by position only (a knob held at its centre could not be turned), so, as RoboGen does before an RL
sub-task, the cup is placed on the knob's front face 60 % of the way from the axis to the rim and
suction is switched on. The learned part is the contact-rich one: leading the held point round the
axis (or out along a button's axis) without losing the hold, dragging the appliance or stalling.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from anomalygen.mjgeom import geom_world_aabbs
from anomalygen.schema import CLOSED_TOL

if TYPE_CHECKING:  # pragma: no cover
    from collections.abc import Callable

    from anomalygen.skills.episode import Episode

POS_SCALE = 10.0  # positions in dm (~unit scale for the networks)
# Physics steps per 7-D action while a part is led, here and in the family's env (skills/learned/part_env.py),
# so a policy is replayed at the rate it learned at (the shipped warm start: 2, as every SAC env here).
FRAMESKIP = 2
OBS_DIM = 17
OFF_AXIS = 0.6  # grasp this fraction of the knob radius away from its axis: a lever for the hold
PRE_CONTACT = 0.04  # m in front of the face before the final approach
BACK_OFF = 0.08  # m the cup retreats along the face normal after letting go


def part_geometry(model, data, joint: str) -> dict:
    """World geometry of a part's joint: body, anchor, unit axis, outward face normal, face centre,
    radius (largest extent perpendicular to the axis) and whether it is a hinge."""
    import mujoco

    from anomalygen.robot.frames import subtree_geoms

    j = model.joint(joint).id
    body = int(model.jnt_bodyid[j])
    hinge = model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE
    axis = data.xaxis[j] / np.linalg.norm(data.xaxis[j])
    anchor = data.xanchor[j].copy()
    geoms = np.flatnonzero(subtree_geoms(model, body))
    glo, ghi = geom_world_aabbs(model, data)
    lo, hi = glo[geoms].min(axis=0), ghi[geoms].max(axis=0)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    centre = (lo + hi) / 2
    # the face looks away from the appliance: along +-axis, the side the part sticks out to
    root = int(model.body_rootid[body])
    sign = 1.0 if np.dot(centre - data.xpos[root], axis) >= 0 else -1.0
    normal = sign * axis
    rel = corners - anchor
    depth = float(np.max(rel @ normal))
    perp = rel - np.outer(rel @ axis, axis)
    radius = float(np.max(np.linalg.norm(perp, axis=1))) / np.sqrt(2.0) if hinge else 0.0
    on_axis = anchor + np.dot(centre - anchor, axis) * axis if hinge else centre
    face = on_axis + (depth - np.dot(on_axis - anchor, normal)) * normal
    return {"joint": j, "body": body, "hinge": bool(hinge), "axis": axis, "anchor": anchor,
            "normal": normal, "face": face, "radius": radius}


def grasp_point(model, data, joint: str, k: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(point on the part's front face to hold, outward normal): off the axis for a knob, so that
    leading the held point round the axis turns it; the face centre for a button. ``k`` picks the
    side of the axis (0: above it, then the two sides, then below), for when a first one is blocked."""
    g = part_geometry(model, data, joint)
    p = g["face"]
    if g["hinge"]:
        side = np.cross(g["axis"], [0.0, 0.0, 1.0])
        if np.linalg.norm(side) < 0.3:  # a vertical axis: any horizontal direction will do
            side = np.cross(g["axis"], [1.0, 0.0, 0.0])
        side /= np.linalg.norm(side)
        # above the axis when it is horizontal: the cup comes from the front and above
        up = np.cross(side, g["axis"])
        up = up if up[2] >= 0 else -up
        first = up if abs(g["axis"][2]) < 0.7 else side
        other = side if abs(g["axis"][2]) < 0.7 else up
        p = p + OFF_AXIS * g["radius"] * (first, other, -other, -first)[k % 4]
    return p, g["normal"]


GRASP_TRIES = 2  # sides of the knob axis tried (above it, then beside it) before giving up


def grasp_part(ep: Episode, joint: str) -> tuple[bool, str]:
    """Place the base, bring the cup to the part's face and hold it by suction (position only)."""
    from anomalygen.robot.ik import quat_z_to

    drv = ep.driver
    m, d = drv.model, drv.data
    body = m.body(int(m.jnt_bodyid[m.joint(joint).id])).name
    why = f"cup did not reach the face of {body}"
    for side in range(GRASP_TRIES):
        p, n = grasp_point(m, d, joint, side)
        quat = quat_z_to(-n)
        pre = p + n * PRE_CONTACT
        if not (drv.place_base_near(p, side=n, reach_poses=[(pre, quat)]) or drv.place_base_near(p, side=n)
                or drv.place_base_near(p)):
            why = f"no collision-free base pose near {joint}"
            continue
        if not drv.reach_planned((pre, pre + n * 0.10), quat):
            drv.goto(pre + n * 0.10, quat, max_steps=200, tol=0.02)
        drv.goto(pre, quat, max_steps=120, tol=0.01)
        for k in range(24):
            p, n = grasp_point(m, d, joint, side)
            drv.goto(p + n * (PRE_CONTACT - 0.0025 * k), quat, max_steps=10, tol=0.004)
            if drv.agent.cup_distance(d, body) < drv.agent.SUCTION_RANGE * 0.8:
                if drv.agent.grab(d, body):
                    return True, f"cup holds {body}" + (" (second side)" if side else "")
        drv.goto(drv.site + n * 0.08, max_steps=40)  # back out before trying the other side
    return False, why


MAX_HOLDER_SHIFT = 0.03  # m the appliance carrying a led control may move before the lead stops
MAX_HOLDER_TILT = 0.08  # rad it may tip or turn


def _holder_moved(model, data, body: int, pos0: np.ndarray, rot0: np.ndarray) -> bool:
    """Has the body carrying the part been dragged or tipped since (pos0, rot0)?"""
    rel = rot0.T @ data.xmat[body].reshape(3, 3)
    angle = float(np.arccos(np.clip((np.trace(rel) - 1.0) / 2.0, -1.0, 1.0)))
    return bool(np.linalg.norm(data.xpos[body] - pos0) > MAX_HOLDER_SHIFT or angle > MAX_HOLDER_TILT)


def lead_held_part(ep: Episode, readout: PartReadout, act, *, horizon: int,
                   tol: float = CLOSED_TOL, past_ok: bool = False) -> tuple[bool, int, str]:
    """Drive the held part with ``act(observation) -> 7-D action`` on the Driver, at the env's frameskip,
    until it is within ``tol`` of its travel from off or ``horizon`` control steps pass: the learned
    skill's replay (a policy) and the scripted primitive (:func:`reference_action`) alike. The lead stops
    when the appliance carrying the part is being dragged or tipped (a cup running off a small dial's
    circle hauls a fan heater over by it): a stopped lead lets go and may try again, a tipped heater
    stays tipped. With ``past_ok`` a part led beyond off (into its stop) is off too: a button pulled out
    past its stop by the weld sprang back in when let go. Returns (off, control steps taken, why it
    stopped early or "")."""
    drv = ep.driver
    m, d = drv.model, drv.data
    holder = int(m.body_parentid[readout.body])
    pos0, rot0 = d.xpos[holder].copy(), d.xmat[holder].reshape(3, 3).copy()
    fs, drv.frameskip = drv.frameskip, FRAMESKIP
    def off() -> bool:
        f = readout.fraction(d)
        return f <= tol if past_ok else abs(f) <= tol

    t, ok, why = 0, off(), ""
    try:
        while t < horizon and not ok:
            readout.agent.apply_action(d, act(readout.observation(m, d, t, horizon)))
            t += 1
            drv.step()
            ok = off()
            if not ok and holder and _holder_moved(m, d, holder, pos0, rot0):
                why = f"stopped: {m.body(holder).name} was being dragged or tipped"
                break
    finally:
        drv.frameskip = fs
    return ok, t, why


RELEASE_HOLD = 2  # control steps the arm holds still, target on the held point, before suction goes off
BACK_OFF_STEP = 0.004  # m a control step while the cup backs away from the part (as parts.py backs off a lid)


def pulled_to_off(model, data, readout: PartReadout) -> bool:
    """Does the part come out towards the cup to go off (a latched push button: on is pressed in)?"""
    if readout.hinge:
        return False
    j = readout.jid
    towards_off = readout.off_sign() * data.xaxis[j] / np.linalg.norm(data.xaxis[j])
    return bool(np.dot(towards_off, part_geometry(model, data, readout.joint)["normal"]) > 0.5)


def let_go(ep: Episode, joint: str, *, pulled: bool = False) -> None:
    """Bring the arm's target onto the held point and hold still, switch suction off and back the cup
    slowly away along the part's face normal, wrist straightened. A lead leaves the target ahead of the
    cup (up to the leash): released there, the arm lunges after it (its wrist knocked a fan heater
    over); a target on the cup instead pulls the part back by the stretched weld (a dial sprang back).
    A part ``pulled`` out to off is let go as it is: the target ahead of it is away from the appliance,
    and brought onto the held point it pressed a 5 mm button 1.5 mm back in."""
    drv = ep.driver
    m, d = drv.model, drv.data
    a = drv.agent
    body = int(m.jnt_bodyid[m.joint(joint).id])
    eq = a.suction_eq(m.body(body).name)
    if eq >= 0 and d.eq_active[eq] and not pulled:
        held = d.xpos[body] + d.xmat[body].reshape(3, 3) @ m.eq_data[eq, 0:3]
        d.mocap_pos[a.mocap], d.mocap_quat[a.mocap] = held, d.xquat[a.cup]
        for _ in range(RELEASE_HOLD):
            drv.step()
    a.release(d)
    normal = part_geometry(m, d, joint)["normal"]
    dp, drv.dp = drv.dp, BACK_OFF_STEP
    try:
        drv.goto(drv.site + BACK_OFF * normal, max_steps=40)
    finally:
        drv.dp = dp
    drv.straighten_wrist(lift=0.1, lift_steps=30)


@dataclass
class Lead:
    """What one hold of a part and its lead towards off came to (:func:`hold_and_lead`)."""

    held: bool  # the cup took hold of the part
    why: str  # grasp_part's word: what the cup holds, or why it did not take hold
    off: bool = False  # the lead brought the part to off (before letting go)
    steps: int = 0  # control steps the lead took
    stopped: str = ""  # why the lead stopped early ("" when it did not)
    led_to: float = 0.0  # the joint's value where the lead left it, before letting go


def hold_and_lead(ep: Episode, readout: PartReadout, policy: Callable[[], Callable[[np.ndarray], np.ndarray]], *,
                  horizon: int, tol: float = CLOSED_TOL) -> Lead:
    """The family's one sequence, for the scripted primitive and the learned skill alike: hold the part
    by suction (:func:`grasp_part`), lead it towards off (:func:`lead_held_part`) with the actions of
    ``policy()``, asked once the part is held (the learned skill fine-tunes there, on a snapshot of the
    hold, and puts the state back), and let go (:func:`let_go`). A part that comes out towards the cup to
    go off (:func:`pulled_to_off`) counts as off led past it and is let go where it is. Nothing is led
    or let go when the cup does not take hold."""
    held, why = grasp_part(ep, readout.joint)
    if not held:
        return Lead(False, why)
    act = policy()
    drv = ep.driver
    pulled = pulled_to_off(drv.model, drv.data, readout)
    off, t, stopped = lead_held_part(ep, readout, act, horizon=horizon, tol=tol, past_ok=pulled)
    led_to = float(drv.data.joint(readout.joint).qpos[0])
    let_go(ep, readout.joint, pulled=pulled)
    return Lead(True, why, off, t, stopped, led_to)


class PartReadout:
    """The family's observation and success for one joint, on any (model, data) of the scene.

    Used both by :class:`~anomalygen.skills.learned.part_env.PartTurnEnv` and by the lead on the Driver's
    data (a policy's replay, the scripted reference), so training and execution read the same numbers.
    """

    def __init__(self, model, joint: str, closed: float, far: float):
        import mujoco

        from anomalygen.robot.agent import Agent

        self.joint, self.closed, self.far = joint, float(closed), float(far)
        self.jid = model.joint(joint).id
        self.adr = int(model.jnt_qposadr[self.jid])
        self.body = int(model.jnt_bodyid[self.jid])
        self.hinge = model.jnt_type[self.jid] == mujoco.mjtJoint.mjJNT_HINGE
        self.span = max(abs(self.far - self.closed), 1e-9)
        self.agent = Agent(model)
        self.eq = self.agent.suction_eq(model.body(self.body).name)

    def fraction(self, data) -> float:
        """Signed fraction of the travel still to go to off (1 = fully on)."""
        return float((data.qpos[self.adr] - self.closed) / (self.far - self.closed)) if self.far != self.closed else 0.0

    def off_sign(self, frac: float = 1.0) -> float:
        """+1 or -1: the way along the joint's axis that takes the part towards off from a signed
        travel ``frac`` (the on side by default; past off, the way back)."""
        return float(-np.sign(self.far - self.closed) * (1.0 if frac >= 0 else -1.0))

    def held_point(self, model, data) -> np.ndarray | None:
        """World position of the suction anchor on the part, None when the part is not held."""
        if self.eq is None or self.eq < 0 or not data.eq_active[self.eq]:
            return None
        r = data.xmat[self.body].reshape(3, 3)
        return data.xpos[self.body] + r @ model.eq_data[self.eq, 0:3]

    def observation(self, model, data, t: int, horizon: int) -> np.ndarray:
        cup = data.xpos[self.agent.cup]  # the cup body: the suction weld anchors the part at its origin
        held = self.held_point(model, data)
        point = cup.copy() if held is None else held
        axis = data.xaxis[self.jid] / np.linalg.norm(data.xaxis[self.jid])
        frac = self.fraction(data)
        towards_off = self.off_sign(frac)
        if self.hinge:
            lever = point - data.xanchor[self.jid]
            lever = lever - np.dot(lever, axis) * axis
            move = np.cross(axis, lever)
            move = towards_off * move / (np.linalg.norm(move) + 1e-9)
        else:
            lever = np.zeros(3)
            move = towards_off * axis
        return np.concatenate([POS_SCALE * (point - cup), move, POS_SCALE * lever,
                               [abs(frac), 1.0 if frac >= 0 else -1.0],
                               [0.0 if held is None else 1.0, t / horizon],
                               axis * float(self.hinge), [float(self.hinge)]]).astype(np.float64)

    def at_off(self, data) -> bool:
        return abs(self.fraction(data)) <= CLOSED_TOL


REFERENCE_MOVE = 0.6  # the reference's action along the part's path (0.6 * 3 cm a step)


def reference_action(obs: np.ndarray, move: float = REFERENCE_MOVE) -> np.ndarray:
    """A scripted turn from the observation alone: move the held point along its towards-off direction
    (``move`` of a full action step) and pull the cup back onto it, suction on. Used for demonstrations
    that seed the warm start's training (``benchmarks/train_warm_start.py --demos``) and, paced, by the
    scripted primitive (``skills/scripted/controls.py``); on the built scenes it turns a held knob to
    off in 15-26 steps, but it has no notion of a hold that slips or a part that jams."""
    a = np.zeros(7)
    a[:3] = np.clip(move * obs[3:6] + 0.5 * obs[0:3], -1.0, 1.0)
    a[6] = 1.0
    return a
