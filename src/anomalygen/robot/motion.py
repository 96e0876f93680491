"""Collision-free joint-space motion planning with OMPL's BIT*, checked by MuJoCo's own collider.

Why joint space and MuJoCo collisions: the primitives (approach, move_to) need arm paths that avoid
the furniture of a generated scene, and the scene *is* a MuJoCo model; asking MuJoCo whether a
configuration has robot-vs-world contacts (with a small safety margin on the robot's geoms) needs no
second geometry model. Why BIT* with a cost threshold: BIT* is the paper's planner; left alone it
keeps improving until its time budget is spent, so the objective's cost threshold is set very high
and it returns the first solution it finds (then shortcut-simplified and interpolated).

Self-collisions between arm links are not checked (MuJoCo's panda model excludes most link pairs and
joint limits keep the rest apart in practice); contacts between the robot and bodies named in
``allowed_bodies`` (a held object, say) are ignored.
"""

from __future__ import annotations

import numpy as np

_SEEDED = False


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


def plan_path(model, data, joint_names, q_goal, *, time_limit: float = 2.0, seed: int = 0, margin: float = 0.01,
              allowed_bodies=(), max_step: float = 0.05, checker: CollisionChecker | None = None
              ) -> list[np.ndarray] | None:
    """Collision-free joint path from the joints' values in ``data`` to ``q_goal``, or None.

    The path is simplified (shortcutting) and interpolated to steps of at most ``max_step`` rad;
    its first waypoint is the start and its last the goal. None when start or goal is in collision
    or BIT* finds no exact solution within ``time_limit`` seconds.
    """
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    global _SEEDED
    ou.setLogLevel(ou.LogLevel.LOG_ERROR)  # BIT* warns on every query that ends at the time limit
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
    si.setStateValidityChecker(lambda s: checker.valid([s[i] for i in range(n)]))
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
    status = planner.solve(float(time_limit))
    if not pdef.hasExactSolution():
        return None
    del status
    path = pdef.getSolutionPath()
    og.PathSimplifier(si).simplifyMax(path)
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
