"""Planned arm motion for the primitives: IK goal, BIT* joint path, executed under joint position control.

Why: the primitives' straight mocap lines sweep the arm through whatever lies between the cup and its
goal (a shelf board, a table edge). Here the arm instead goes to the goal configuration along a
collision-checked joint-space path (``motion.plan_path``, OMPL BIT*), executed with real dynamics.

How the arm is driven: a :class:`~anomalygen.robot.driver.Driver` keeps the agent in control mode
``"ee_delta_pose"`` (arm limp, the cup pulled by the ``ee_track`` weld). For the planned motion it
switches to ``"arm_joint_pos"`` (the arm's position servos with their compiled gains, weld off); the
path's waypoints become the actuators' ``ctrl``, one per control step through ``Driver.step`` (so the
step counter and video hook see every step). At the end it switches back to ``"ee_delta_pose"``,
which puts the mocap target on the cup, so ``Driver.goto`` carries on from there. The suction welds are separate equality constraints, so a held
object stays attached throughout.

A held object is carried by the collision checker too: ``motion.CollisionChecker`` only moves the
arm joints, which would leave a held free object hanging where it was, so :class:`CarryingChecker`
places it at its grasp-relative pose for every checked configuration and counts its contacts with
the world as collisions.

Determinism: IK restarts draw from ``numpy.random.default_rng(seed)``. OMPL's RNG is process-global
and seeded once, by the first ``plan_path`` call of the process (later seeds are ignored), and every
planner call advances it. So a given sequence of calls from a fresh process repeats exactly, but one
call's path depends on the planning calls made before it in that process. The planner's budget is a
number of validity checks (``max_checks``), not seconds, so a busy machine plans the same paths as an
idle one, only slower; ``plan_s`` (wall time) is reported and never decides anything.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from anomalygen.robot.agent import Agent
from anomalygen.robot.frames import relative_pose, subtree_geoms
from anomalygen.robot.motion import CHECKS_PER_IDLE_S, CollisionChecker

#: Validity checks one planned arm motion (or re-homing) may spend: what the old 1 s wall-clock limit
#: of these calls allowed on an idle core (``plan_path``'s own default stands for its old 2 s).
ARM_PLAN_CHECKS = 1 * CHECKS_PER_IDLE_S


@dataclass
class ArmMotionResult:
    ok: bool
    reason: str
    path_len: int = 0  # waypoints of the executed (re-timed) joint path
    plan_s: float = 0.0  # IK + planning wall time (reported, never used to decide)
    steps: int = 0  # control steps executed (Driver.step calls)
    site_error: float = float("nan")  # cup face to target after the motion, metres
    margin: float = 0.0  # clearance the path keeps (smaller than asked when the arm started closer)


class CarryingChecker(CollisionChecker):
    """``CollisionChecker`` that moves the held object with the cup and checks it against the world.

    The object's pose relative to the cup is ``rel`` (``(relpos, relquat)``) or else taken from ``data``
    at construction (the suction weld holds it there). Contacts between the object and the robot are ignored; contacts between the
    object and anything else count, with the same ``margin`` as the robot's geoms (see
    :func:`widen_body_margins`, which it applies).
    """

    def __init__(self, model, data, joint_names, held: str, *, margin: float = 0.01, allowed_bodies=(), rel=None):
        import mujoco


        super().__init__(model, data, joint_names, margin=margin, allowed_bodies=(*allowed_bodies, held))
        body = model.body(held).id
        jnt = model.body_jntadr[body]
        if jnt < 0 or model.jnt_type[jnt] != mujoco.mjtJoint.mjJNT_FREE:
            raise ValueError(f"held object {held!r} has no free joint; it cannot be carried by the checker")
        self._qadr_obj = int(model.jnt_qposadr[jnt])
        self._cup = model.body(Agent.CUP_BODY).id
        if rel is None:
            mujoco.mj_kinematics(self.model, self.data)
            rel = relative_pose(self.data.xpos[self._cup], self.data.xquat[self._cup],
                                self.data.xpos[body], self.data.xquat[body])
        self._rel = rel
        self._held = subtree_geoms(model, body)
        self.model.geom_margin[self._held] = np.maximum(self.model.geom_margin[self._held], margin)
        widen_body_margins(self, margin)

    def contacts(self, q) -> list[tuple[int, int]]:
        mj, m, d = self._mj, self.model, self.data
        d.qpos[self.qadr] = q
        mj.mj_kinematics(m, d)
        relpos, relquat = self._rel
        pos = d.xpos[self._cup] + d.xmat[self._cup].reshape(3, 3) @ relpos
        quat = np.zeros(4)
        mj.mju_mulQuat(quat, d.xquat[self._cup], relquat)
        d.qpos[self._qadr_obj:self._qadr_obj + 3] = pos
        d.qpos[self._qadr_obj + 3:self._qadr_obj + 7] = quat
        bad = super().contacts(q)  # robot vs world (the object is an allowed body); reruns kinematics
        for i in range(d.ncon):
            g1, g2 = int(d.contact.geom1[i]), int(d.contact.geom2[i])
            h1, h2 = self._held[g1], self._held[g2]
            if h1 != h2 and not self._robot[g2 if h1 else g1]:
                bad.append((g1, g2))
        return bad


def retime(path, max_step: float) -> list[np.ndarray]:
    """Waypoints no more than ``max_step`` rad apart on any joint (one per control step)."""
    from anomalygen.robot.motion import interpolate

    return interpolate(path, max_step) if len(path) > 1 else [np.asarray(path[0], dtype=float)]


def _ik_goal(m, d, checker: CollisionChecker, target_pos, quat, rng: np.random.Generator, attempts: int):
    """Collision-free IK solution, (q, why-not): the one reached from the current arm if valid, else the
    nearer (largest joint change) of the first two from random restarts."""
    from anomalygen.robot.ik import solve_ik

    q0 = d.qpos[checker.qadr].copy()
    lim = np.array([m.jnt_range[m.joint(n).id] for n in Agent.ARM_JOINTS])
    found, any_ik = [], False
    for k in range(attempts):
        q_init = q0 if k == 0 else rng.uniform(lim[:, 0], lim[:, 1])
        res = solve_ik(m, d, Agent.CUP_SITE, Agent.ARM_JOINTS, target_pos, quat, q_init=q_init)
        if not res.success:
            continue
        any_ik = True
        q = res.qpos[checker.qadr].copy()
        if checker.valid(q):
            found.append(q)
            if k == 0 or len(found) >= 2:  # the solution grown from the current arm is the natural one
                break
    if not found:
        return None, ("ik solutions in collision" if any_ik else "ik failed")
    return min(found, key=lambda q: float(np.max(np.abs(q - q0)))), ""


def _reference_state(model, data):
    """A scratch copy of ``data`` with the base where its servos hold it (their ``ctrl``).

    Why: the base is a stiff but soft position servo; a preceding mocap move or kinematic base
    placement can leave it centimetres off its set point and still moving. IK and the path are
    computed for the pose the base settles at, not for a transient one.
    """
    import mujoco


    ref = mujoco.MjData(model)
    ref.qpos[:] = data.qpos
    ref.mocap_pos[:], ref.mocap_quat[:] = data.mocap_pos, data.mocap_quat
    for name in Agent.BASE_JOINTS:
        ref.joint(name).qpos[0] = data.actuator(name).ctrl[0]
    mujoco.mj_kinematics(model, ref)
    return ref


def _held_relative_pose(model, data, held: str):
    """Pose of the held body in the cup frame, from ``data``'s joint values."""
    import mujoco


    sc = mujoco.MjData(model)
    sc.qpos[:] = data.qpos
    mujoco.mj_kinematics(model, sc)
    cup, body = model.body(Agent.CUP_BODY).id, model.body(held).id
    return relative_pose(sc.xpos[cup], sc.xquat[cup], sc.xpos[body], sc.xquat[body])


def _clearance(checker: CollisionChecker, q) -> float:
    """Smallest distance of the bad contacts at ``q`` (inf when there are none)."""
    bad = set(checker.contacts(q))
    c = checker.data.contact
    dists = [float(c.dist[i]) for i in range(checker.data.ncon) if (int(c.geom1[i]), int(c.geom2[i])) in bad]
    return min(dists, default=float("inf"))


def widen_body_margins(checker: CollisionChecker, margin: float) -> None:
    """Put the checker's margin on the *bodies* of its widened geoms too.

    Why: MuJoCo's broad phase culls body pairs with ``body_margin``, fixed at compile time, so a
    margin raised only in ``geom_margin`` (all ``CollisionChecker`` does) goes unseen whenever the
    two bodies' bounding boxes do not already overlap: a cup 6 mm above a free-standing box was
    reported clear at a 10 mm margin.
    """
    m = checker.model
    for b in set(m.geom_bodyid[m.geom_margin >= margin].tolist()):
        m.body_margin[b] = max(m.body_margin[b], margin)


def _checker(model, data, held, rel, margin, allowed_bodies) -> CollisionChecker:

    if held is not None:
        return CarryingChecker(model, data, Agent.ARM_JOINTS, held, margin=margin, allowed_bodies=allowed_bodies,
                               rel=rel)
    chk = CollisionChecker(model, data, Agent.ARM_JOINTS, margin=margin, allowed_bodies=allowed_bodies)
    widen_body_margins(chk, margin)
    return chk


def move_arm_planned(drv, target_pos, quat, *, max_checks: int = ARM_PLAN_CHECKS, seed: int = 0, allowed_bodies=(),
                     max_steps: int = 400, margin: float = 0.01, joint_speed: float = 1.0, tol: float = 0.01,
                     ik_attempts: int = 8) -> ArmMotionResult:
    """Move the cup face (``suction_site``) to ``target_pos`` with the cup oriented as ``quat`` along a
    collision-free joint path of the 7 arm joints (base fixed), executed with the arm's position servos.

    When IK or planning fails nothing is moved and ``ok`` is False with ``reason`` one of "ik failed",
    "ik solutions in collision", "start in collision", "no path in <n> checks"; the caller then falls
    back to straight-line ``Driver.goto``. The path keeps ``margin`` metres between robot (and held
    object) and world; if the arm already starts closer than that to something (but not touching,
    >= 2 mm), the margin shrinks to half that clearance for this motion. ``joint_speed`` (rad/s) caps
    every joint's commanded speed; the motion ends when all joints are within ``tol`` rad of the goal,
    the arm is nearly still and the base is back at its set point, or after ``max_steps`` control steps
    (then ``ok`` is False, "did not settle", with the arm moved). ``allowed_bodies``: bodies the arm
    may touch; a held object is added and carried automatically.
    """
    from anomalygen.robot.motion import plan_path

    m, d = drv.model, drv.data
    t0 = time.perf_counter()
    held = drv.agent.held(d)
    rel = _held_relative_pose(m, d, held) if held is not None else None
    ref = _reference_state(m, d)
    checker = _checker(m, ref, held, rel, margin, allowed_bodies)
    q0 = d.qpos[checker.qadr].copy()

    def fail(reason: str) -> ArmMotionResult:
        return ArmMotionResult(False, reason, plan_s=round(time.perf_counter() - t0, 4), margin=margin)

    if not checker.valid(q0):
        gap = _clearance(checker, q0)
        if gap < 0.002:
            return fail("start in collision")
        margin = gap / 2
        checker = _checker(m, ref, held, rel, margin, allowed_bodies)
    goal, why = _ik_goal(m, ref, checker, target_pos, quat, np.random.default_rng(seed), ik_attempts)
    if goal is None:
        return fail(why)
    path = plan_path(m, ref, Agent.ARM_JOINTS, goal, max_checks=max_checks, seed=seed, checker=checker)
    if path is None:
        return fail(f"no path in {max_checks} checks")
    plan_s = round(time.perf_counter() - t0, 4)
    settled, n_way, steps = follow_joint_path(drv, path, max_steps=max_steps, joint_speed=joint_speed, tol=tol)
    err = float(np.linalg.norm(drv.site - np.asarray(target_pos, dtype=float)))
    return ArmMotionResult(settled, "reached" if settled else "did not settle", n_way, plan_s, steps,
                           round(err, 5), margin)


def rehome(drv, *, max_checks: int = ARM_PLAN_CHECKS, seed: int = 0, max_steps: int = 300) -> bool:
    """Bring the arm back to its home configuration (cup down, folded in), planned when possible.

    Pulling a drawer or a door leaves the wrist turned sideways; a straight mocap move from there to a
    cup-down pose can wind the wrist into the furniture. From home every approach starts clean. When
    the arm starts touching something the joints are interpolated straight to home; when home itself
    collides (a drawer just pulled open in front of the robot) nothing moves and False is returned.
    """
    from anomalygen.robot.motion import plan_path

    m, d = drv.model, drv.data
    held = drv.agent.held(d)
    rel = _held_relative_pose(m, d, held) if held is not None else None
    ref = _reference_state(m, d)
    checker = _checker(m, ref, held, rel, 0.005, ())
    q0 = d.qpos[checker.qadr].copy()
    home = np.asarray(Agent.HOME_ARM, dtype=float)
    if not checker.valid(home):
        return False  # home itself collides (an opened drawer right in front): stay put
    path = plan_path(m, ref, Agent.ARM_JOINTS, home, max_checks=max_checks, seed=seed, checker=checker) \
        if checker.valid(q0) else None
    settled, _, _ = follow_joint_path(drv, path or [q0, home], max_steps=max_steps)
    return settled


def follow_joint_path(drv, path, *, max_steps: int = 400, joint_speed: float = 1.0, tol: float = 0.01):
    """Execute an arm joint path under position control; returns (settled, waypoints, steps)."""

    m, d, agent = drv.model, drv.data, drv.agent
    goal = np.asarray(path[-1], dtype=float)
    qadr = [m.jnt_qposadr[m.joint(n).id] for n in Agent.ARM_JOINTS]
    # ---- execute: joint position control along the path
    dt = drv.frameskip * m.opt.timestep
    way = retime(path, joint_speed * dt)
    acts = [m.actuator(n).id for n in Agent.ARM_JOINTS]
    dadr = [m.jnt_dofadr[m.joint(n).id] for n in Agent.ARM_JOINTS]
    bq = [m.jnt_qposadr[m.joint(n).id] for n in Agent.BASE_JOINTS]
    base_set = np.array([d.actuator(n).ctrl[0] for n in Agent.BASE_JOINTS])
    s0 = drv.steps
    agent.set_control_mode(d, "arm_joint_pos")  # the servos aim where the arm is
    settled = False
    try:
        for q in way[1:]:
            d.ctrl[acts] = q
            drv.step()
        while drv.steps - s0 < max_steps:
            err = np.max(np.abs(d.qpos[qadr] - goal))
            if (err < tol and np.max(np.abs(d.qvel[dadr])) < 0.05
                    and np.max(np.abs(d.qpos[bq] - base_set)) < 0.003):
                settled = True
                break
            drv.step()
    finally:
        agent.set_control_mode(d, "ee_delta_pose")  # mocap on the cup, arm limp again, weld on
        for name, v in zip(Agent.BASE_JOINTS, base_set, strict=True):
            d.actuator(name).ctrl[0] = v  # the mode switch re-aims the base where it is; keep the set point
    return settled, len(way), drv.steps - s0
