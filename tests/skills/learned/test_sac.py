"""The door env's physics and reward, and SAC's success-based checkpoint selection."""

import numpy as np
import pytest

from support.door_env import DoorCloseEnv, make_door_env


def _scripted_close(env, seed):
    env.reset(seed=seed)
    rewards = []
    for i in range(100):
        st = env.state()
        h, ee = np.asarray(st["objects"]["cabinet_0:door_handle"]["pos"]), np.asarray(st["ee"]["pos"])
        tgt = h + np.array([-0.05, -0.08, 0]) if i < 40 else h + np.array([0.2, 0.2, 0])
        a = np.zeros(7)
        a[:3] = np.clip((tgt - ee) / 0.03, -1, 1)
        _, r, _, _, info = env.step(a)
        rewards.append(r)
    return info, rewards


def test_door_env_passes_gymnasiums_checker_and_is_registered():
    import gymnasium as gym
    from gymnasium.utils.env_checker import check_env

    from support.door_env import DOOR_ENV_ID

    check_env(DoorCloseEnv(), skip_render_check=True)
    env = gym.make(DOOR_ENV_ID)
    assert env.spec.max_episode_steps == env.unwrapped.horizon == 100
    _, info = env.reset(seed=0)
    _, _, _, _, info = env.step(np.zeros(7))
    assert info["is_success"] is False
    env.close()


def test_pushing_the_door_closes_it_and_the_reward_rises():
    env = DoorCloseEnv()
    for seed in range(2):
        info, rewards = _scripted_close(env, seed)
        assert info["success"] and env.door < 0.1
        assert np.mean(rewards[-10:]) > np.mean(rewards[:10]) + 1.0
    # doing nothing leaves it open; the registration's TimeLimit ends the episode
    env = make_door_env()
    env.reset(seed=0)
    for _ in range(100):
        _, _, _, trunc, info = env.step(np.zeros(7))
    assert trunc and not info["success"] and env.unwrapped.door > 0.4


@pytest.mark.slow
def test_sac_keeps_the_best_success_checkpoint():
    from anomalygen.skills.learned.sac import train_sac

    model, res = train_sac(make_door_env, 200, eval_every=100, eval_episodes=1, learning_starts=50)
    assert [c["step"] for c in res.curve] == [0, 100, 200]
    best = max(res.curve, key=lambda c: (c["success"], c["return"]))
    assert res.best_step == best["step"] and res.best_success == best["success"]
    net = model.policy.actor.latent_pi
    assert [layer.out_features for layer in net if hasattr(layer, "out_features")] == [256, 256, 256]


@pytest.mark.slow
def test_sac_improves_the_evaluation_return_within_a_small_budget():
    """Same evaluation seeds before and after: the trained policy's mean return is clearly higher."""
    from anomalygen.skills.learned.sac import train_sac

    _, res = train_sac(make_door_env, 2000, seed=0, eval_every=1000, eval_episodes=4, learning_starts=500)
    initial = res.curve[0]["return"]
    assert res.curve[0]["step"] == 0 and res.best_step > 0
    assert max(c["return"] for c in res.curve[1:]) > initial + 20.0


def test_evaluation_reads_is_success_and_the_callback_replaces_evalcallback_as_a_basecallback():
    """Success is the final step's ``info["is_success"]`` (Gymnasium's and SB3's key), and the
    success-keeping evaluation is a BaseCallback of its own, not an EvalCallback with its insides
    overridden. The env and the policy here are test doubles: one step, success by the action's sign."""
    import gymnasium as gym
    from gymnasium import spaces
    from stable_baselines3.common.callbacks import BaseCallback, EvalCallback

    from anomalygen.skills.learned.sac import SACResult, evaluate_policy, success_eval_callback

    class OneStep(gym.Env):
        observation_space = spaces.Box(-1.0, 1.0, shape=(1,))
        action_space = spaces.Box(-1.0, 1.0, shape=(1,))

        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            return np.zeros(1, dtype=np.float32), {}

        def step(self, action):
            ok = bool(action[0] > 0)
            return np.zeros(1, dtype=np.float32), 1.0, True, False, {"is_success": ok, "success": not ok}

    class Sign:
        def __init__(self, a):
            self.a = a

        def predict(self, obs, deterministic=True):
            return np.array([self.a], dtype=np.float32), None

    assert evaluate_policy(Sign(1.0), OneStep(), 3, seed=0) == (1.0, 1.0)
    assert evaluate_policy(Sign(-1.0), OneStep(), 3, seed=0) == (0.0, 1.0)
    result = SACResult(best_success=-1.0, best_return=-np.inf, best_step=0, steps=0, wall_s=0.0)
    cb = success_eval_callback(OneStep(), eval_every=10, episodes=1, seed=0, result=result, stop_at=None)
    assert isinstance(cb, BaseCallback) and not isinstance(cb, EvalCallback)
