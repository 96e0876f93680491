"""Collision-free joint-space motion planning with OMPL's BIT*, checked by MuJoCo's own collider.

Why joint space and MuJoCo collisions: the primitives (approach, move_to) need arm paths that avoid
the furniture of a generated scene, and the scene *is* a MuJoCo model; asking MuJoCo whether a
configuration has robot-vs-world contacts (with a small safety margin on the robot's geoms) needs no
second geometry model. Why BIT* with a cost threshold: BIT* is the paper's planner; left alone it
keeps improving until its budget is spent, so the objective's cost threshold is set very high and it
returns the first solution it finds (then shortcut-simplified and interpolated).

Why the budget counts validity checks, not seconds: a wall-clock limit lets the machine's load decide
whether a hard query finds its path before giving up, so the same item on the same code took another
path, or fell back to a straight move, and ran a different number of control steps when the machine
was busy. A query now ends after ``max_checks`` state-validity checks (each one ``mj_collision`` of
the scene, where nearly all of its time goes); a wall-clock cap a hundred times longer than that
budget takes on an idle core stays only as a safety net that normal runs never reach.

Self-collisions between arm links are not checked (MuJoCo's panda model excludes most link pairs and
joint limits keep the rest apart in practice); contacts between the robot and bodies named in
``allowed_bodies`` (a held object, say) are ignored.
"""

from __future__ import annotations

import logging

import numpy as np

_SEEDED = False
log = logging.getLogger(__name__)

#: Validity checks BIT* makes per second of one idle core on built household scenes: measured on the
#: development machine (an AMD EPYC vCPU) by thread CPU time over unsolvable arm queries in ten built
#: scenes, 2,400-7,300 per CPU second (docs/learn.md); so a budget converted from seconds gives about
#: what the old wall-clock limit allowed on an idle core (twice that in the heaviest scenes, 0.7x in the
#: lightest).
CHECKS_PER_IDLE_S = 5000
#: A query's default budget, in validity checks: what the old 2 s limit allowed on an idle core.
PLAN_MAX_CHECKS = 2 * CHECKS_PER_IDLE_S
#: The wall-clock safety net as a multiple of the time the check budget takes on an idle core. The
#: shared 2-core development machine, under its usual load, runs a query 6-8 times slower than its
#: CPU time; 100 leaves another tenfold margin, so only a pathologically slow checker reaches it.
WALL_CAP_FACTOR = 100.0


class CollisionChecker:
    """``valid(q)``: no robot-vs-world contact within ``margin`` with the joints at ``q``.

    Works on a private copy of the model (the margin is written into it) and a scratch ``MjData``
    starting from the caller's state, so the caller's simulation is never touched.
    """

    def __init__(self, model, data, joint_names, *, margin: float = 0.01, allowed_bodies=()):
        import copy

        import mujoco

        from anomalygen.robot.agent import Agent
        from anomalygen.robot.ik import joint_dofs

        self._mj = mujoco
        self.model = copy.copy(model)
        self.data = mujoco.MjData(self.model)
        self.data.qpos[:] = data.qpos
        self.data.mocap_pos[:] = data.mocap_pos
        self.data.mocap_quat[:] = data.mocap_quat
        self.qadr, _ = joint_dofs(model, joint_names)
        robot = np.zeros(model.ngeom, dtype=bool)
        robot[Agent.geom_ids(model)] = True
        allowed = set()
        for name in allowed_bodies:
            allowed.add(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name))
        self._robot = robot
        self._allowed = np.array([model.geom_bodyid[g] in allowed for g in range(model.ngeom)], dtype=bool)
        self.model.geom_margin[robot] = np.maximum(self.model.geom_margin[robot], margin)
        self.checks = 0

    def contacts(self, q) -> list[tuple[int, int]]:
        """Robot-vs-world geom pairs in contact (within the margin) at configuration ``q``."""
        mj, m, d = self._mj, self.model, self.data
        d.qpos[self.qadr] = q
        mj.mj_kinematics(m, d)
        mj.mj_collision(m, d)
        self.checks += 1
        bad = []
        for i in range(d.ncon):
            g1, g2 = int(d.contact.geom1[i]), int(d.contact.geom2[i])
            r1, r2 = self._robot[g1], self._robot[g2]
            if r1 == r2:  # world-world (resting objects) or robot self contact
                continue
            other = g2 if r1 else g1
            if not self._allowed[other]:
                bad.append((g1, g2))
        return bad

    def valid(self, q) -> bool:
        return not self.contacts(q)


def joint_bounds(model, joint_names) -> np.ndarray:
    """(n, 2) limits of the joints from ``model.jnt_range`` (unlimited joints get +-pi)."""
    import mujoco

    out = []
    for name in joint_names:
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        out.append(model.jnt_range[j] if model.jnt_limited[j] else (-np.pi, np.pi))
    return np.asarray(out, dtype=float)


def interpolate(path, max_step: float = 0.05) -> list[np.ndarray]:
    """Densify a waypoint list so no joint moves more than ``max_step`` rad between neighbours."""
    out = [np.asarray(path[0], dtype=float)]
    for a, b in zip(path[:-1], path[1:], strict=True):
        a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
        n = max(1, int(np.ceil(np.max(np.abs(b - a)) / max_step)))
        out.extend(a + (b - a) * (k / n) for k in range(1, n + 1))
    return out


def path_is_valid(checker: CollisionChecker, path, max_step: float = 0.02) -> bool:
    return all(checker.valid(q) for q in interpolate(path, max_step))


def wall_cap_s(max_checks: int) -> float:
    """Seconds after which a query of ``max_checks`` checks is stopped anyway (the safety net)."""
    return WALL_CAP_FACTOR * max_checks / CHECKS_PER_IDLE_S


def check_budget(count, max_checks: int, wall_s: float):
    """OMPL termination condition: ``count()`` (validity checks so far) reached ``max_checks``, or
    ``wall_s`` seconds passed. The planner evaluates it itself between iterations (no polling thread),
    so the check budget ends a query at the same iteration on any machine (the edge being checked when
    the count passes ``max_checks`` is finished first: up to some tens of checks more)."""
    from ompl import base as ob

    spent = ob.PlannerTerminationCondition(lambda: count() >= max_checks)
    return ob.plannerOrTerminationCondition(spent, ob.timedPlannerTerminationCondition(float(wall_s)))


def restart_seed_sequence(seed: int) -> None:
    """Start OMPL's process-global seed sequence over, as a fresh process seeded by :func:`plan_path`
    with ``seed`` would have it. Called when an execution starts, so that what it plans depends on its
    own seed alone and not on what the process planned before (a skill test that passed on its own
    failed after another test file had planned in the same pytest worker). OMPL reports an error
    when sampling has already started, but the restart takes effect: the same seed gives the same
    draws again."""
    from ompl import util as ou

    global _SEEDED
    ou.setLogLevel(ou.LogLevel.LOG_NONE)
    ou.RNG.setSeed(int(seed) + 1)
    ou.setLogLevel(ou.LogLevel.LOG_ERROR)
    _SEEDED = True


def plan_path(model, data, joint_names, q_goal, *, max_checks: int = PLAN_MAX_CHECKS, seed: int = 0,
              margin: float = 0.01, allowed_bodies=(), max_step: float = 0.05,
              checker: CollisionChecker | None = None) -> list[np.ndarray] | None:
    """Collision-free joint path from the joints' values in ``data`` to ``q_goal``, or None.

    The path is simplified (shortcutting) and interpolated to steps of at most ``max_step`` rad;
    its first waypoint is the start and its last the goal. None when start or goal is in collision
    or BIT* finds no exact solution within ``max_checks`` state-validity checks (or, as a safety net
    that logs a warning, within :func:`wall_cap_s` seconds). Given the OMPL seed and the calls before
    it in the process, the result does not depend on the machine's speed or load.
    """
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    global _SEEDED
    ou.setLogLevel(ou.LogLevel.LOG_ERROR)  # BIT* warns on every query that ends at its budget
    if not _SEEDED:  # OMPL's seed is process-global and can only be set before its first sample
        ou.RNG.setSeed(int(seed) + 1)
        _SEEDED = True
    checker = checker or CollisionChecker(model, data, joint_names, margin=margin, allowed_bodies=allowed_bodies)
    q_start = np.asarray(data.qpos[checker.qadr], dtype=float)
    q_goal = np.asarray(q_goal, dtype=float)
    if not (checker.valid(q_start) and checker.valid(q_goal)):
        return None
    n = len(joint_names)
    lim = joint_bounds(model, joint_names)
    # A joint pushed a little past its soft limit (the arm leaning on a part it just slid) would put
    # the start outside the space and BIT* would fail at once, leaving a straight fallback that sweeps
    # through the furniture: the bounds take in where the arm and the goal really are.
    lim = np.stack([np.minimum(lim[:, 0], np.minimum(q_start, q_goal)),
                    np.maximum(lim[:, 1], np.maximum(q_start, q_goal))], axis=1)
    space = ob.RealVectorStateSpace(n)
    bounds = ob.RealVectorBounds(n)
    for i, (lo, hi) in enumerate(lim):
        bounds.setLow(i, float(lo))
        bounds.setHigh(i, float(hi))
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    checks = [0]

    def valid(s) -> bool:
        checks[0] += 1
        return checker.valid([s[i] for i in range(n)])

    si.setStateValidityChecker(valid)
    # 1 % of the space's extent between motion checks (~0.1 rad on the arm)
    si.setStateValidityCheckingResolution(0.01)
    si.setup()
    start, goal = space.allocState(), space.allocState()
    for i in range(n):
        start[i], goal[i] = float(q_start[i]), float(q_goal[i])
    pdef = ob.ProblemDefinition(si)
    pdef.setStartAndGoalStates(start, goal)
    objective = ob.PathLengthOptimizationObjective(si)
    objective.setCostThreshold(ob.Cost(1e9))  # accept the first solution instead of spending the budget
    pdef.setOptimizationObjective(objective)
    planner = og.BITstar(si)
    planner.setProblemDefinition(pdef)
    planner.setup()
    cap = wall_cap_s(max_checks)
    planner.solve(check_budget(lambda: checks[0], int(max_checks), cap))
    if not pdef.hasExactSolution():
        if checks[0] < max_checks:
            log.warning("BIT* stopped by the %.0f s safety net after %d of %d checks: this result depends on "
                        "the machine's speed", cap, checks[0], max_checks)
        return None
    path = pdef.getSolutionPath()
    og.PathSimplifier(si).simplifyMax(path)  # no time limit: it stops when shortcutting no longer helps
    way = [np.array([path.getState(k)[i] for i in range(n)]) for k in range(path.getStateCount())]
    way[0], way[-1] = q_start, q_goal
    return interpolate(way, max_step)


def goal_from_pose(model, data, site: str, pos, quat=None, *, joint_names=None, seed: int = 0,
                   restarts: int = 5) -> np.ndarray | None:
    """Arm joint values putting ``site`` at ``pos`` (and ``quat``), by IK; None when IK fails."""
    from anomalygen.robot.agent import Agent
    from anomalygen.robot.ik import joint_dofs, solve_ik

    joint_names = list(joint_names or Agent.ARM_JOINTS)
    res = solve_ik(model, data, site, joint_names, pos, quat, rng=np.random.default_rng(seed), restarts=restarts)
    if not res.success:
        return None
    qadr, _ = joint_dofs(model, joint_names)
    return res.qpos[qadr].copy()
