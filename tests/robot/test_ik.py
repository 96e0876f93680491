"""DLS inverse kinematics on the project's Franka: reaches poses with the cup aligned to a normal."""

import mujoco
import numpy as np
import pytest

from anomalygen.robot.agent import Agent
from anomalygen.robot.ik import quat_z_to, site_pose, solve_ik
from support.testbed import build


@pytest.fixture(scope="module")
def bed():
    return build()


@pytest.mark.parametrize("target, normal", [([0.55, 0.2, 0.5], [0, 0, -1]), ([0.5, -0.1, 0.08], [0, 0, -1]),
                                            ([0.6, 0.1, 0.45], [1, 0, 0])])
def test_ik_reaches_pose_and_aligns_cup(bed, target, normal):
    m, d = bed.model, bed.data
    quat = quat_z_to(normal)
    res = solve_ik(m, d, "ee_site", Agent.ARM_JOINTS, target, quat, rng=np.random.default_rng(0), restarts=3)
    assert res.success
    scratch = mujoco.MjData(m)
    scratch.qpos[:] = res.qpos
    mujoco.mj_kinematics(m, scratch)
    pos, q = site_pose(m, scratch, "ee_site")
    assert np.linalg.norm(pos - target) < 0.005
    zaxis = scratch.site_xmat[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "ee_site")].reshape(3, 3)[:, 2]
    assert np.dot(zaxis, normal) > 0.99
    # the caller's data is untouched
    assert np.allclose(d.qpos, bed.data.qpos)


def test_unreachable_target_reports_failure(bed):
    res = solve_ik(bed.model, bed.data, "ee_site", Agent.ARM_JOINTS, [3.0, 0.0, 0.5], iterations=100)
    assert not res.success and res.pos_error > 1.0
