"""Judging only when the caller asks (``anomalygen.make_env(scene, judge=...)``) and the vector env
for Stable-Baselines3 (``anomalygen.make_vec_env``): with judging off no info holds a verdict and
the referee is never called, at an episode's end too; judging at the end (the default) puts the
verdict in the last info; the vector env steps its envs, resets them and trains SAC. Behaviour
only: the step cost is measured by ``benchmarks/bench_env_step.py``."""

from __future__ import annotations

import numpy as np
import pytest
from tests.scene.conftest import make_task

import anomalygen
from anomalygen.config import Settings
from anomalygen.schema import Verdict

# one hazard and nothing else: the cheapest scene the referee can judge
QUIET_MIX = {"clutter": 0, "near_misses": 0, "multi_hazard": 0.0, "hazard_free": 0.0, "real_assets": False}


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    from anomalygen.scene.build import build_scene

    out = tmp_path_factory.mktemp("judged_env") / "knife"
    task = make_task("t-knife-edge", "store_sharp_objects", "Table", "kitchen_knife", "counter_edge")
    build_scene(task, seed=0, settings=Settings(build=QUIET_MIX), out_dir=out)
    return out


@pytest.fixture
def referee_calls(monkeypatch):
    """Every call of the referee's judge, which still answers as before."""
    import anomalygen.referee.settle as settle

    calls, real = [], settle.judge

    def spy(*args, **kwargs):
        calls.append(args[0])
        return real(*args, **kwargs)

    monkeypatch.setattr(settle, "judge", spy)
    return calls


def _episode(env, steps):
    env.reset(seed=0)
    out = []
    for _ in range(steps):
        *_, terminated, truncated, info = env.step(np.zeros(7, dtype=np.float32))
        out.append((terminated or truncated, info))
    return out


@pytest.mark.parametrize("off", ["never", False])
def test_judging_off_gives_no_verdict_and_never_calls_the_referee(scene, referee_calls, off):
    env = anomalygen.make_env(scene, judge=off, horizon=3)
    assert env.judging == "never"
    for _ in range(2):  # two episodes, each to its end
        steps = _episode(env, 3)
        assert [end for end, _ in steps] == [False, False, True]
        assert all(info == {} for _, info in steps)  # the bare env's info, at the end too
    assert referee_calls == [] and env.verdict is None
    verdict = env.verdict_now()  # asked for: judged once, the episode left as it was
    assert isinstance(verdict, Verdict) and env.verdict is verdict and len(referee_calls) == 1
    env.close()


@pytest.mark.parametrize("kwargs", [{}, {"judge": "end"}, {"judge": True}])
def test_judging_at_the_end_is_the_default_and_puts_the_verdict_in_the_last_info(scene, referee_calls, kwargs):
    env = anomalygen.make_env(scene, horizon=3, **kwargs)
    assert env.judging == "end"
    steps = _episode(env, 3)
    assert all("verdict" not in info for _, info in steps[:2])
    end = steps[-1][1]
    assert isinstance(end["verdict"], Verdict) and end["is_success"] is end["verdict"].resolved is False
    assert "own_check" in end and len(referee_calls) == 1  # once per episode, at its end
    env.close()


def test_judging_can_be_switched_between_episodes(scene, referee_calls):
    env = anomalygen.make_env(scene, judge="never", horizon=2)
    assert "verdict" not in _episode(env, 2)[-1][1]
    env.judging = "end"  # an evaluation episode
    assert "verdict" in _episode(env, 2)[-1][1] and len(referee_calls) == 1
    env.close()


def test_an_unknown_judging_mode_is_refused_before_the_scene_loads(tmp_path):
    with pytest.raises(ValueError, match="'end', 'never'"):
        anomalygen.make_env(tmp_path / "no-scene", judge="always")


def test_the_vector_env_steps_its_envs_and_resets_them_at_their_ends(scene, referee_calls):
    from stable_baselines3.common.vec_env import DummyVecEnv

    venv = anomalygen.make_vec_env(scene, 2, horizon=3, seed=0)
    assert isinstance(venv, DummyVecEnv) and venv.num_envs == 2
    assert venv.get_attr("judging") == ["never", "never"]  # made for training: judging off by default
    first = venv.reset()
    assert first.shape == (2, *venv.observation_space.shape)
    for t in range(3):
        obs, rewards, dones, infos = venv.step(np.zeros((2, 7), dtype=np.float32))
        assert rewards.shape == (2,) and dones.tolist() == [t == 2] * 2
    assert all("terminal_observation" in info and "verdict" not in info for info in infos)
    assert np.array_equal(obs, first)  # reset again, to the same settled start
    assert referee_calls == []
    venv.set_attr("judging", "end")
    for _ in range(3):
        *_, infos = venv.step(np.zeros((2, 7), dtype=np.float32))
    assert all(isinstance(info["verdict"], Verdict) for info in infos) and len(referee_calls) == 2
    venv.close()


def test_sac_learns_on_the_vector_env_without_the_referee(scene, referee_calls):
    from stable_baselines3 import SAC

    venv = anomalygen.make_vec_env(scene, 2, horizon=10, seed=0)
    model = SAC("MlpPolicy", venv, learning_starts=8, batch_size=8, buffer_size=200, gradient_steps=1,
                policy_kwargs={"net_arch": [16]}, seed=0, device="cpu")
    model.learn(total_timesteps=40)
    assert model.num_timesteps == 40 and model.replay_buffer.size() == 20  # 20 steps of 2 envs
    assert referee_calls == []
    venv.close()


@pytest.mark.slow
def test_the_vector_env_runs_its_envs_in_processes(scene):
    from stable_baselines3.common.vec_env import SubprocVecEnv

    venv = anomalygen.make_vec_env(scene, 2, judge="end", subproc=True, horizon=2)
    assert isinstance(venv, SubprocVecEnv)
    venv.reset()
    for _ in range(2):
        *_, dones, infos = venv.step(np.zeros((2, 7), dtype=np.float32))
    assert dones.all() and all(isinstance(info["verdict"], Verdict) for info in infos)
    venv.close()
