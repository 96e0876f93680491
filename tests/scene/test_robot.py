"""The robot model: names other stages rely on, a home pose with the cup down, working suction."""

import mujoco
import numpy as np

from anomalygen.scene import robot, robot_model


def _robot_with_box():
    spec = robot_model.build_robot_spec((0.0, 0.0, 0.0))
    spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[3, 3, 0.1])
    box = spec.worldbody.add_body(name="box_0", pos=[0.5, 0.0, 0.03])
    box.add_freejoint(name="box_0/free")
    box.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.03, 0.03, 0.03], mass=0.2)
    robot_model.add_suction_welds(spec, ["box_0"])
    model = spec.compile()
    data = mujoco.MjData(model)
    robot.set_home(model, data, (0.0, 0.0, 0.0))
    mujoco.mj_forward(model, data)
    return model, data


def test_names_and_home_pose_points_the_cup_down():
    model, data = _robot_with_box()
    for name in robot.ROBOT_JOINTS:
        assert model.joint(name).id >= 0
        assert model.actuator(name).id >= 0
    for site in ("ee_site", "suction_site"):
        assert model.site(site).id >= 0
    z_axis = data.site("ee_site").xmat.reshape(3, 3)[:, 2]
    assert z_axis[2] < -0.99  # cup faces the floor
    # actuators hold the home pose against gravity for a second
    mujoco.mj_step(model, data, nstep=500)
    arm = [data.joint(j).qpos[0] for j in robot.ARM_JOINTS]
    assert np.allclose(arm, robot.HOME_ARM, atol=0.02)


def test_suction_grabs_only_when_touching_and_carries_the_object():
    model, data = _robot_with_box()
    assert not robot.suction_on(model, data)  # nothing within reach of the cup at home
    robot.enable_ee_tracking(model, data)
    cup = data.body("suction")
    offset = cup.xpos - data.site("suction_site").xpos
    data.mocap_quat[0] = cup.xquat
    box_top = data.body("box_0").xpos + [0, 0, 0.03]
    start = data.mocap_pos[0].copy()
    start[:] = cup.xpos
    above = box_top + offset + [0, 0, 0.15]
    for i in range(1500):  # move above the box, then lower the cup onto its top, gradually
        f = min(1.0, i / 600)
        goal = (
            start + f * (above - start)
            if i < 800
            else above + min(1.0, (i - 800) / 400) * (box_top + offset - [0, 0, 0.002] - above)
        )
        data.mocap_pos[0] = goal
        mujoco.mj_step(model, data)
    assert robot.suction_on(model, data)
    assert robot.held_object(model, data) == "box_0"
    before = data.body("box_0").xpos.copy()
    for _ in range(1000):
        data.mocap_pos[0] = box_top + offset + [0, 0, 0.3]
        mujoco.mj_step(model, data)
    assert data.body("box_0").xpos[2] > before[2] + 0.2  # lifted with the cup
    robot.suction_off(model, data)
    mujoco.mj_step(model, data, nstep=1000)
    assert data.body("box_0").xpos[2] < 0.05  # dropped back to the floor
    assert robot.held_object(model, data) is None


def test_torso_lift_raises_the_arm_rigidly():
    """``set_lift`` carries the whole arm up by its value, and it stays there while the arm's
    actuators hold the pose; ``set_home`` lowers it again, where the arm reaches the floor."""
    model, data = _robot_with_box()
    assert robot.lift(model) == 0.0
    z0 = float(data.site("suction_site").xpos[2])
    assert robot.set_lift(model, data, 1.0) == robot.LIFT_MAX  # clipped to the column's travel
    assert abs(float(data.site("suction_site").xpos[2]) - z0 - robot.LIFT_MAX) < 1e-9
    mujoco.mj_step(model, data, nstep=500)
    assert abs(float(data.site("suction_site").xpos[2]) - z0 - robot.LIFT_MAX) < 0.01
    assert model.geom("torso_column").id in set(robot.robot_geom_ids(model).tolist())
    robot.set_home(model, data, (0.0, 0.0, 0.0))
    mujoco.mj_forward(model, data)
    assert robot.lift(model) == 0.0 and abs(float(data.site("suction_site").xpos[2]) - z0) < 1e-6
    assert model.nu == len(robot.ROBOT_JOINTS)  # no new actuator: envs see the same robot
