"""A push closes a hinged door from random open angles using only the joint's kinematics (the scene
query ``joint_motion_direction`` that the part skills use)."""

import numpy as np
import pytest

from anomalygen.skills.geometry import joint_motion_direction
from support.door_env import DoorCloseEnv, push_joint


@pytest.mark.parametrize("seed", [0, 1, 4])
def test_push_closes_door(seed):
    env = DoorCloseEnv(open_range=(0.5, 1.4))
    env.reset(seed=seed)
    start = env.door
    ok, _, _ = push_joint(env, "cabinet_0:door_hinge", 0.0, "cabinet_0:door_handle")
    assert start > 0.45
    assert ok and env.door < 0.1 and env.success()


def test_motion_direction_is_tangent_to_the_hinge():
    env = DoorCloseEnv()
    env.reset(seed=0)
    h = env.data.site_xpos[env._site_h].copy()
    v = joint_motion_direction(env.model, env.data, "cabinet_0:door_hinge", h)
    assert abs(v[2]) < 1e-6 and abs(np.linalg.norm(v) - 1) < 1e-9
    # moving the joint a little moves the handle along v
    env.data.joint("cabinet_0:door_hinge").qpos[0] += 0.01
    import mujoco

    mujoco.mj_kinematics(env.model, env.data)
    step = env.data.site_xpos[env._site_h] - h
    assert np.dot(step / np.linalg.norm(step), v) > 0.99
