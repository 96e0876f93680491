"""The Gymnasium env: Gymnasium's own checker, TimeLimit from the registry, determinism under a seed,
suction carries an object, success reaches ``info["is_success"]``."""

import gymnasium as gym
import numpy as np

from anomalygen.scene.env import ENV_ID, HORIZON, make_env


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
    assert env.unwrapped.horizon is None and env.unwrapped.scene.bindings
    obs, info = env.reset(seed=1)
    assert env.observation_space.contains(obs) and info == {"is_success": False}
    steps, truncated = 0, False
    while not truncated:
        obs, _, terminated, truncated, info = env.step(np.zeros(7))
        steps += 1
        assert not terminated and info["is_success"] is False
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
    import mujoco

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


def test_suction_attaches_and_carries(built_scenes):
    env = make_env(built_scenes["knife_edge"], horizon=1000)
    obs, _ = env.reset(seed=0)
    L = env.obs_layout
    name = env.scene.bindings["$hazard"]
    k = env.task_objects.index(name)
    pos = lambda o: o[L["object_pos"]][3 * k : 3 * k + 3]  # noqa: E731
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
