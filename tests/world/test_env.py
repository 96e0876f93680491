"""The Gymnasium env: Gymnasium's own checker, TimeLimit from the registry, determinism under a seed,
suction carries an object, success reaches ``info["is_success"]`` only from the caller's own check,
every object observed alike. (What it must not show the robot: tests/world/test_perception.py.)"""

import gymnasium as gym
import mujoco
import numpy as np

from anomalygen.runfolder import read_model
from anomalygen.schema import SceneSpec
from anomalygen.world.env import ENV_ID, HORIZON, make_env


def test_spaces_and_step(built_scenes):
    env = make_env(built_scenes["knife_edge"], frameskip=2, horizon=5)
    obs, info = env.reset(seed=0)
    assert env.action_space.shape == (7,)
    assert obs.shape == env.observation_space.shape
    L = env.obs_layout
    assert L["robot_qpos"].stop - L["robot_qpos"].start == 10
    for _ in range(5):
        obs, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        assert np.all(np.isfinite(obs))
    assert truncated and not terminated
    img = env.render()
    assert img.shape == (240, 320, 3) and img.std() > 5
    env.close()


def test_passes_gymnasiums_env_checker(built_scenes):
    from gymnasium.utils.env_checker import check_env

    env = make_env(built_scenes["knife_edge"], frameskip=2, horizon=5)
    check_env(env)
    env.close()


def test_registered_with_gymnasium_and_time_limited_by_it(built_scenes):
    env = gym.make(ENV_ID, scene_dir=built_scenes["floor"], frameskip=2)
    assert env.spec.max_episode_steps == HORIZON  # the EnvSpec is Gymnasium's, the scene lives elsewhere
    assert env.unwrapped.horizon is None and not env.unwrapped.scene.bindings
    obs, info = env.reset(seed=1)
    assert env.observation_space.contains(obs) and info == {}  # no success check given: none claimed
    steps, truncated = 0, False
    while not truncated:
        obs, _, terminated, truncated, info = env.step(np.zeros(7))
        steps += 1
        assert not terminated and "is_success" not in info
    assert steps == HORIZON
    graph = env.unwrapped.graph()  # reads the scene, not the EnvSpec gym.make put in env.spec
    assert {o.name for o in graph.objects} == {o.name for o in env.unwrapped.scene.objects}
    env.close()


def test_rotation_turns_the_cup_about_its_own_axes(built_scenes):
    env = make_env(built_scenes["floor"], horizon=1000)
    env.reset(seed=0)
    d, r = env.data, env.agent
    before = d.mocap_quat[r.mocap].copy()
    env.step(np.array([0, 0, 0, 0, 0, 1.0, -1.0]))  # +dr about the cup's z axis
    want = np.zeros(4)
    mujoco.mju_mulQuat(want, before, np.array([np.cos(env.max_delta_rot / 2), 0, 0, np.sin(env.max_delta_rot / 2)]))
    assert np.allclose(d.mocap_quat[r.mocap], want, atol=1e-8)


def test_reset_is_deterministic_under_seed(built_scenes):
    env = make_env(built_scenes["floor"], init_noise=0.02)
    actions = np.random.default_rng(0).uniform(-1, 1, size=(10, 7))
    runs = []
    for _ in range(2):
        obs, _ = env.reset(seed=7)
        traj = [obs]
        for a in actions:
            traj.append(env.step(a)[0])
        runs.append(np.array(traj))
    assert np.array_equal(runs[0], runs[1])
    other, _ = env.reset(seed=8)
    assert not np.array_equal(other, runs[0][0])


def test_delta_action_moves_the_end_effector(built_scenes):
    env = make_env(built_scenes["floor"], horizon=1000)
    obs, _ = env.reset(seed=0)
    L = env.obs_layout
    start = obs[L["ee_pos"]].copy()
    for _ in range(40):
        obs, *_ = env.step(np.array([0, 0, 1, 0, 0, 0, -1.0]))
    assert obs[L["ee_pos"]][2] > start[2] + 0.2  # 40 steps of up to +3 cm (the agent's step) upward


def test_every_object_observed_in_name_order_from_the_compiled_sensors(built_scenes):
    for key, folder in built_scenes.items():
        env = make_env(folder, horizon=5)
        obs, _ = env.reset(seed=0)
        spec = read_model(folder / "scene.json", SceneSpec)
        assert env.object_names == sorted(o.name for o in spec.objects), key  # clutter and decoys too
        assert env._use_sensors, key  # the scene compiled a sensor for each of them
        L = env.obs_layout
        assert L["object_pos"].stop - L["object_pos"].start == 3 * len(spec.objects)
        assert L["suction"].stop == obs.size  # suction last, after the objects
        for k, name in enumerate(env.object_names):
            assert np.allclose(obs[L["object_pos"]][3 * k : 3 * k + 3], env.data.body(name).xpos, atol=1e-6)
        env.close()


def _base_within_reach_of(env, point, distance: float = 0.55) -> None:
    """Stand the base ``distance`` from ``point`` on the side of the robot's home, facing it (the scene
    starts the robot wherever it likes; this env's actions move the arm only)."""
    away = -np.asarray(point[:2]) / np.linalg.norm(point[:2])
    xy = np.asarray(point[:2]) + distance * away
    env.agent.set_home(env.data, (xy[0], xy[1], float(np.arctan2(-away[1], -away[0]))))
    mujoco.mj_forward(env.model, env.data)
    env.agent.set_control_mode(env.data, "ee_delta_pose")


def test_suction_attaches_and_carries(built_scenes):
    env = make_env(built_scenes["knife_edge"], horizon=1000)
    env.reset(seed=0)
    L = env.obs_layout
    name = read_model(built_scenes["knife_edge"] / "scene.json", SceneSpec).bindings["$hazard"]
    k = env.object_names.index(name)
    pos = lambda o: o[L["object_pos"]][3 * k : 3 * k + 3]  # noqa: E731
    _base_within_reach_of(env, env.data.body(name).xpos)
    obs, *_ = env.step(np.array([0, 0, 0, 0, 0, 0, -1.0]))
    target = pos(obs).copy()
    above = target + [0, 0, 0.12]
    for _ in range(150):  # hover above the object first, then come straight down onto it
        ee = obs[L["ee_pos"]]
        obs, *_ = env.step(np.r_[np.clip((above - ee) / env.max_delta_pos, -1, 1), 0, 0, 0, -1.0])
    for _ in range(150):
        ee = obs[L["ee_pos"]]
        obs, *_ = env.step(np.r_[np.clip((target - ee) / env.max_delta_pos, -1, 1), 0, 0, 0, 1.0])
        if env.held:
            break
    assert env.held == name
    lifted_from = pos(obs)[2]
    for _ in range(40):
        obs, *_ = env.step(np.array([0, 0, 1, 0, 0, 0, 1.0]))
    assert pos(obs)[2] > lifted_from + 0.1
    assert obs[L["suction"]][0] == 1.0
    for _ in range(5):
        obs, *_ = env.step(np.array([0, 0, 0, 0, 0, 0, -1.0]))
    assert env.held is None


def test_reward_and_success_hooks(built_scenes):
    calls = []
    env = make_env(
        built_scenes["floor"],
        reward_fn=lambda e: calls.append(e.t) or 0.5,
        success_fn=lambda e: e.t >= 2,
    )
    env.reset(seed=0)
    _, r, term, _, info = env.step(np.zeros(7))
    assert r == 0.5 and not term and info == {"is_success": False}
    _, _, term, _, info = env.step(np.zeros(7))
    assert term and calls == [1, 2] and info == {"is_success": True}
    graph = env.graph()
    assert {o.name for o in graph.objects} == {o.name for o in env.scene.objects}
