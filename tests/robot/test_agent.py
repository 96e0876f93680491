"""The agent: names other stages rely on, a home pose with the cup down, the grab rule, control
modes, the lift and the action mapping."""

import mujoco
import numpy as np

from anomalygen.robot.agent import Agent


def _robot_with_box():
    spec = Agent.build_spec((0.0, 0.0, 0.0))
    spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[3, 3, 0.1])
    box = spec.worldbody.add_body(name="box_0", pos=[0.5, 0.0, 0.03])
    box.add_freejoint(name="box_0/free")
    box.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.03, 0.03, 0.03], mass=0.2)
    Agent.add_suction_welds(spec, ["box_0"])
    model = spec.compile()
    data = mujoco.MjData(model)
    Agent(model).set_home(data, (0.0, 0.0, 0.0))
    mujoco.mj_forward(model, data)
    return model, data


def test_names_and_home_pose_points_the_cup_down():
    model, data = _robot_with_box()
    for name in Agent.ROBOT_JOINTS:
        assert model.joint(name).id >= 0
        assert model.actuator(name).id >= 0
    for site in ("ee_site", "suction_site"):
        assert model.site(site).id >= 0
    z_axis = data.site("ee_site").xmat.reshape(3, 3)[:, 2]
    assert z_axis[2] < -0.99  # cup faces the floor
    # actuators hold the home pose against gravity for a second
    mujoco.mj_step(model, data, nstep=500)
    arm = [data.joint(j).qpos[0] for j in Agent.ARM_JOINTS]
    assert np.allclose(arm, Agent.HOME_ARM, atol=0.02)


def test_the_home_pose_boxes_hold_the_arm_at_its_home_pose():
    """The builder keeps objects out of HOME_ARM_BOXES: every arm link and the cup must lie in them."""
    model, data = _robot_with_box()
    boxes = [(np.array([a[0] for a in box]), np.array([a[1] for a in box])) for box in Agent.HOME_ARM_BOXES]

    def boxed(p) -> bool:
        return any(np.all(p >= lo) and np.all(p <= hi) for lo, hi in boxes)

    links = [b for b in range(model.nbody) if model.body(b).name.startswith(Agent.ARM_LINK_PREFIX)]
    assert len(links) == 8
    for b in links:
        assert boxed(data.xpos[b]), model.body(b).name
    assert boxed(data.body(Agent.CUP_BODY).xpos) and boxed(data.site(Agent.CUP_SITE).xpos)
    assert not boxed(np.array([0.6, 0.0, 1.0]))  # half a metre ahead of the cup is free


def test_suction_grabs_only_within_range_and_carries_the_object():
    model, data = _robot_with_box()
    agent = Agent(model)
    assert not agent.grab(data)  # nothing within reach of the cup at home
    agent.set_control_mode(data, "ee_delta_pose")
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
    assert agent.grab(data)
    assert agent.held(data) == "box_0"
    assert model.eq_data[agent.suction_eq("box_0"), 10] == 1.0  # a free body is held rigidly
    before = data.body("box_0").xpos.copy()
    for _ in range(1000):
        data.mocap_pos[0] = box_top + offset + [0, 0, 0.3]
        mujoco.mj_step(model, data)
    assert data.body("box_0").xpos[2] > before[2] + 0.2  # lifted with the cup
    agent.release(data)
    mujoco.mj_step(model, data, nstep=1000)
    assert data.body("box_0").xpos[2] < 0.05  # dropped back to the floor
    assert agent.held(data) is None


def test_torso_lift_raises_the_arm_rigidly():
    """``set_lift`` carries the whole arm up by its value, and it stays there while the arm's
    actuators hold the pose; ``set_home`` lowers it again, where the arm reaches the floor."""
    model, data = _robot_with_box()
    agent = Agent(model)
    assert agent.lift() == 0.0
    z0 = float(data.site("suction_site").xpos[2])
    assert agent.set_lift(data, 1.0) == Agent.LIFT_MAX  # clipped to the column's travel
    assert abs(float(data.site("suction_site").xpos[2]) - z0 - Agent.LIFT_MAX) < 1e-9
    mujoco.mj_step(model, data, nstep=500)
    assert abs(float(data.site("suction_site").xpos[2]) - z0 - Agent.LIFT_MAX) < 0.01
    assert model.geom("torso_column").id in set(Agent.geom_ids(model).tolist())
    agent.set_home(data, (0.0, 0.0, 0.0))
    mujoco.mj_forward(model, data)
    assert agent.lift() == 0.0 and abs(float(data.site("suction_site").xpos[2]) - z0) < 1e-6
    assert model.nu == len(Agent.ROBOT_JOINTS)  # no new actuator: envs see the same robot


def test_control_modes_switch_the_arm_between_the_weld_and_its_servos():
    """``ee_delta_pose``: arm servos limp, the cup welded to the mocap target at the cup's pose;
    ``arm_joint_pos``: the servos' compiled gains back, aimed where the arm is, the weld off. An
    unknown mode is refused with the modes the robot has."""
    import pytest

    model, data = _robot_with_box()
    agent = Agent(model)
    acts = [model.actuator(n).id for n in Agent.ARM_JOINTS]
    gain, bias = model.actuator_gainprm[acts].copy(), model.actuator_biasprm[acts].copy()
    agent.set_control_mode(data, "ee_delta_pose")
    assert not model.actuator_gainprm[acts].any() and data.eq_active[agent.track] == 1
    assert np.array_equal(data.mocap_pos[agent.mocap], data.xpos[agent.cup])
    agent.set_control_mode(data, "arm_joint_pos")
    assert np.array_equal(model.actuator_gainprm[acts], gain) and np.array_equal(model.actuator_biasprm[acts], bias)
    assert data.eq_active[agent.track] == 0
    assert np.array_equal(data.ctrl[acts], [data.joint(j).qpos[0] for j in Agent.ARM_JOINTS])
    with pytest.raises(ValueError, match="ee_delta_pose, arm_joint_pos"):
        agent.set_control_mode(data, "torque")


def test_one_action_mapping_with_the_agents_step_size():
    """A full +x action moves the target by ``STEP_POS`` (leashed to the cup), entries beyond
    [-1, 1] are clipped, and the last entry toggles suction by the grab rule."""
    model, data = _robot_with_box()
    agent = Agent(model)
    agent.set_control_mode(data, "ee_delta_pose")
    before = data.mocap_pos[agent.mocap].copy()
    a = agent.apply_action(data, np.array([3.0, 0, 0, 0, 0, 0, -1.0], dtype=np.float32))
    assert a.tolist() == [1.0, 0, 0, 0, 0, 0, -1.0]
    assert np.allclose(data.mocap_pos[agent.mocap] - before, [Agent.STEP_POS, 0, 0], atol=1e-12)
    assert agent.held(data) is None  # nothing in range of the cup at home: the grab finds nothing
    agent.apply_action(data, np.r_[np.zeros(6), 1.0])
    assert agent.held(data) is None


def _reference_move(data, agent, action):
    """The action mapping written in numpy and MuJoCo's own functions, as it read before the scalar
    maths of ``Agent._move_target``: the target after one action, computed on copies."""
    a = np.clip(np.asarray(action, dtype=float), -1.0, 1.0)
    cup, lim = data.xpos[agent.cup], Agent.TARGET_LEASH
    pos = cup + np.clip(data.mocap_pos[agent.mocap] + Agent.STEP_POS * a[:3] - cup, -lim, lim)
    n = np.linalg.norm(a[3:6])
    dq, q = np.zeros(4), np.zeros(4)
    mujoco.mju_axisAngle2Quat(dq, a[3:6] / (n + 1e-9), Agent.STEP_ROT * min(1.0, n))
    mujoco.mju_mulQuat(q, data.mocap_quat[agent.mocap], dq)
    return pos, q / np.linalg.norm(q)


def test_the_action_mappings_scalar_maths_is_numpys_and_mujocos_bit_for_bit():
    """Every env's hot path computes the target in Python scalars (leash comparisons, the axis-angle
    quaternion with math.sin/cos): the same bits as numpy's clip and norm and MuJoCo's
    mju_axisAngle2Quat, so trajectories (and the learning curves pinned on them) are unchanged.
    Actions in range and beyond it, a zero rotation, tiny and leashed moves, the arm moving between."""
    model, data = _robot_with_box()
    agent = Agent(model)
    agent.set_control_mode(data, "ee_delta_pose")
    rng = np.random.default_rng(0)
    for i in range(300):
        action = rng.uniform(-1.5, 1.5, 7).astype(np.float32)
        if i % 5 == 0:
            action[3:6] = 0.0  # no rotation: the zero-angle branch
        elif i % 5 == 1:
            action[3:6] *= 1e-8  # a rotation below the axis's 1e-9 guard's scale
        action[6] = -1.0
        pos, quat = _reference_move(data, agent, action)
        agent.apply_action(data, action)
        assert np.array_equal(data.mocap_pos[agent.mocap], pos), i
        assert np.array_equal(data.mocap_quat[agent.mocap], quat), i
        mujoco.mj_step(model, data, 2)
