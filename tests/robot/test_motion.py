"""BIT* joint-space planning on the test scene: collision-free paths, around an obstacle, within a
budget of validity checks that makes the path independent of the machine's speed."""

import logging

import numpy as np
import pytest

from anomalygen.robot.agent import Agent
from support.planning import obstacle_query, plan_obstacle_query, pregrasp_goal
from support.testbed import scene_with_obstacle


@pytest.fixture(scope="module")
def pregrasp():
    """Home scene and the arm configuration 15 cm above the table's box, cup pointing down."""
    m, d = scene_with_obstacle()
    return m, d, pregrasp_goal(m, d)


def test_path_to_pregrasp_is_collision_free(pregrasp):
    from anomalygen.robot.ik import site_pose
    from anomalygen.robot.motion import CollisionChecker, interpolate, plan_path

    m, d, g = pregrasp
    path = plan_path(m, d, Agent.ARM_JOINTS, g, seed=0)
    assert path is not None and len(path) >= 2
    checker = CollisionChecker(m, d, Agent.ARM_JOINTS)
    assert np.allclose(path[0], d.qpos[checker.qadr]) and np.allclose(path[-1], g)
    assert all(np.max(np.abs(b - a)) <= 0.05 + 1e-9 for a, b in zip(path[:-1], path[1:], strict=True))
    assert all(checker.valid(q) for q in interpolate(path, 0.02))
    # the last waypoint really is above the box
    import mujoco

    sc = mujoco.MjData(m)
    sc.qpos[:] = d.qpos
    sc.qpos[checker.qadr] = path[-1]
    mujoco.mj_kinematics(m, sc)
    pos, _ = site_pose(m, sc, "ee_site")
    assert np.linalg.norm(pos - (d.body("box_0").xpos + [0, 0, 0.15])) < 0.01


def test_planner_goes_around_an_obstacle_and_stops_at_the_first_solution():
    from anomalygen.robot.motion import PLAN_MAX_CHECKS, CollisionChecker, interpolate, plan_path

    m, d, g = obstacle_query()
    checker = CollisionChecker(m, d, Agent.ARM_JOINTS)
    q0 = d.qpos[checker.qadr].copy()
    assert checker.valid(q0) and checker.valid(g)
    assert not all(checker.valid(q) for q in interpolate([q0, g], 0.02))  # the straight way collides

    before = checker.checks
    path = plan_path(m, d, Agent.ARM_JOINTS, g, seed=0, checker=checker)
    assert path is not None
    assert checker.checks - before < PLAN_MAX_CHECKS / 4  # the cost threshold makes BIT* return its first solution
    # BIT* keeps the 1 cm margin at its own checking resolution (~0.1 rad); between two checks the arm
    # may pass closer than that (2 of 40 OMPL seeds did), but it never touches: no contact at 0.02 rad
    touching = CollisionChecker(m, d, Agent.ARM_JOINTS, margin=0.0)
    assert all(touching.valid(q) for q in interpolate(path, 0.02))


def test_goal_in_collision_gives_none(pregrasp):
    from anomalygen.robot.motion import plan_path

    m, d, _ = pregrasp
    q = d.qpos[[m.joint(n).qposadr[0] for n in Agent.ARM_JOINTS]].copy()
    q[1] = 1.7  # shoulder far forward and down: the arm is in the floor/table
    q[3] = -0.1
    from anomalygen.robot.motion import CollisionChecker

    assert not CollisionChecker(m, d, Agent.ARM_JOINTS).valid(q)
    assert plan_path(m, d, Agent.ARM_JOINTS, q, max_checks=500) is None


def test_the_same_query_gives_the_same_path_on_a_much_slower_machine():
    """The budget counts validity checks, not seconds: with every check slowed down (a loaded machine),
    a query planned in a fresh process finds exactly the path an unhindered one finds, only later,
    even when that takes longer than the old wall-clock limit (2 s) allowed."""
    from anomalygen.procs import child_pool
    from anomalygen.robot.motion import CHECKS_PER_IDLE_S, PLAN_MAX_CHECKS

    runs = []
    for delay in (0.0, 0.006):  # 6 ms per check: tens of times what a check costs on this scene
        with child_pool(1) as pool:
            runs.append(pool.submit(plan_obstacle_query, delay, PLAN_MAX_CHECKS).result())
    (fast, n_fast, _), (slow, n_slow, wall_slow) = runs
    assert fast is not None and slow is not None
    assert n_fast == n_slow and wall_slow > PLAN_MAX_CHECKS / CHECKS_PER_IDLE_S
    assert len(fast) == len(slow) and all(np.array_equal(a, b) for a, b in zip(fast, slow, strict=True))


def test_a_budget_too_small_fails_after_that_many_checks_on_any_machine():
    path, checks, _ = plan_obstacle_query(0.002, 40)
    assert path is None
    assert 40 <= checks < 40 + 200  # start and goal, then BIT* stops after the edge that crossed 40


def test_the_wall_clock_safety_net_still_ends_a_query_and_says_so(monkeypatch, caplog):
    from anomalygen.robot import motion

    m, d, g = obstacle_query()
    monkeypatch.setattr(motion, "WALL_CAP_FACTOR", 1e-3)  # 10,000 checks -> 2 ms of wall time
    with caplog.at_level(logging.WARNING, logger="anomalygen.robot.motion"):
        assert motion.plan_path(m, d, Agent.ARM_JOINTS, g, seed=0) is None
    assert "safety net" in caplog.text
