"""BIT* joint-space planning on the test scene: collision-free paths, around an obstacle, fast."""

import time

import numpy as np
import pytest

from anomalygen.robot.agent import Agent
from support.testbed import scene_with_obstacle

_scene = scene_with_obstacle


@pytest.fixture(scope="module")
def pregrasp():
    """Home scene and the arm configuration 15 cm above the table's box, cup pointing down."""
    from anomalygen.robot.ik import quat_z_to
    from anomalygen.robot.motion import goal_from_pose

    m, d = _scene()
    box = d.body("box_0").xpos.copy()
    g = goal_from_pose(m, d, "ee_site", box + [0, 0, 0.15], quat_z_to(np.array([0.0, 0.0, -1.0])))
    assert g is not None
    return m, d, g


def test_path_to_pregrasp_is_collision_free(pregrasp):
    from anomalygen.robot.ik import site_pose
    from anomalygen.robot.motion import CollisionChecker, interpolate, plan_path

    m, d, g = pregrasp
    path = plan_path(m, d, Agent.ARM_JOINTS, g, time_limit=2.0, seed=0)
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


def test_planner_goes_around_an_obstacle_and_stops_at_the_first_solution(pregrasp):
    import mujoco

    from anomalygen.robot.motion import CollisionChecker, interpolate, plan_path

    m0, d0, g = pregrasp
    qadr = CollisionChecker(m0, d0, Agent.ARM_JOINTS).qadr
    q0 = d0.qpos[qadr].copy()
    # put a box where the cup passes a third of the way along the straight joint-space line
    sc = mujoco.MjData(m0)
    sc.qpos[:] = d0.qpos
    sc.qpos[qadr] = q0 + (g - q0) * 0.35
    mujoco.mj_kinematics(m0, sc)
    m, d = _scene(obstacle_at=sc.site_xpos[m0.site("ee_site").id].copy())
    checker = CollisionChecker(m, d, Agent.ARM_JOINTS)
    assert checker.valid(q0) and checker.valid(g)
    assert not all(checker.valid(q) for q in interpolate([q0, g], 0.02))  # the straight way collides

    limit = 10.0
    t0 = time.perf_counter()
    path = plan_path(m, d, Agent.ARM_JOINTS, g, time_limit=limit, seed=0)
    took = time.perf_counter() - t0
    assert path is not None
    assert all(checker.valid(q) for q in interpolate(path, 0.02))
    assert took < limit / 4  # the cost threshold makes BIT* return its first solution


def test_goal_in_collision_gives_none(pregrasp):
    from anomalygen.robot.motion import plan_path

    m, d, _ = pregrasp
    q = d.qpos[[m.joint(n).qposadr[0] for n in Agent.ARM_JOINTS]].copy()
    q[1] = 1.7  # shoulder far forward and down: the arm is in the floor/table
    q[3] = -0.1
    from anomalygen.robot.motion import CollisionChecker

    assert not CollisionChecker(m, d, Agent.ARM_JOINTS).valid(q)
    assert plan_path(m, d, Agent.ARM_JOINTS, q, time_limit=0.5) is None
