"""Motion-planning queries on the test scene, and planning them in a fresh process.

Why a fresh process: OMPL's random generator is process-global and seeded once, so two plans of the
same query in one process start from different generator states. The determinism tests plan each
query in a process of its own, as ``execute_plan`` runs each item.
"""

from __future__ import annotations

import time

import numpy as np

from anomalygen.robot.agent import Agent
from anomalygen.robot.motion import CollisionChecker
from support.testbed import scene_with_obstacle


def pregrasp_goal(m, d) -> np.ndarray:
    """Arm joints putting the ``ee_site`` 15 cm above the table's box, cup pointing down."""
    from anomalygen.robot.ik import quat_z_to
    from anomalygen.robot.motion import goal_from_pose

    g = goal_from_pose(m, d, "ee_site", d.body("box_0").xpos + [0, 0, 0.15], quat_z_to(np.array([0.0, 0.0, -1.0])))
    assert g is not None
    return g


def obstacle_query():
    """(model, data, goal): home to above the table's box, with a 6 cm box where the straight
    joint-space line puts the hand a third of the way along, so BIT* must search for a detour."""
    import mujoco

    m0, d0 = scene_with_obstacle()
    g = pregrasp_goal(m0, d0)
    qadr = CollisionChecker(m0, d0, Agent.ARM_JOINTS).qadr
    q0 = d0.qpos[qadr].copy()
    sc = mujoco.MjData(m0)
    sc.qpos[:] = d0.qpos
    sc.qpos[qadr] = q0 + (g - q0) * 0.35
    mujoco.mj_kinematics(m0, sc)
    m, d = scene_with_obstacle(obstacle_at=sc.site_xpos[m0.site("ee_site").id].copy())
    return m, d, g


class SlowChecker(CollisionChecker):
    """A collision checker that sleeps ``delay_s`` before every check: a machine that many times slower."""

    def __init__(self, *args, delay_s: float = 0.0, **kw):
        super().__init__(*args, **kw)
        self.delay_s = delay_s

    def valid(self, q) -> bool:
        if self.delay_s:
            time.sleep(self.delay_s)
        return super().valid(q)


def plan_obstacle_query(delay_s: float, max_checks: int) -> tuple[list[np.ndarray] | None, int, float]:
    """Plan :func:`obstacle_query` with every check slowed by ``delay_s``: (path, checks, wall seconds).
    Run it in a fresh process (``procs.child_pool``) so OMPL is seeded by this query alone."""
    from anomalygen.robot.motion import plan_path

    m, d, g = obstacle_query()
    checker = SlowChecker(m, d, Agent.ARM_JOINTS, delay_s=delay_s)
    t0 = time.perf_counter()
    path = plan_path(m, d, Agent.ARM_JOINTS, g, max_checks=max_checks, seed=0, checker=checker)
    return path, checker.checks, time.perf_counter() - t0


def planned_arm_move(delay_s: float) -> tuple[bool, int, int, np.ndarray]:
    """``move_arm_planned`` from home to 15 cm above the table's box past :func:`obstacle_query`'s
    obstacle, executed with physics, with every collision check slowed by ``delay_s``:
    (ok, control steps, waypoints, final qpos). Run it in a fresh process (``procs.child_pool``)."""
    from anomalygen.robot import motion
    from anomalygen.robot.arm_motion import move_arm_planned
    from anomalygen.robot.driver import Driver
    from anomalygen.robot.ik import quat_z_to

    contacts = motion.CollisionChecker.contacts

    def slow(self, q):
        time.sleep(delay_s)
        return contacts(self, q)

    motion.CollisionChecker.contacts = slow  # this process only: the caller runs it in a child
    m, d, _ = obstacle_query()
    drv = Driver(m, d)
    drv.settle(5)
    target = d.body("box_0").xpos + np.array([0.0, 0.0, 0.15])
    res = move_arm_planned(drv, target, quat_z_to(np.array([0.0, 0.0, -1.0])), seed=0)
    return res.ok, res.steps, res.path_len, d.qpos.copy()
