"""Gymnasium env for the switch-off family: turn a held knob or switch to off, on one or many scenes.

One env may hold several *starts* (a built scene's model, a physics snapshot taken right after
:func:`~anomalygen.skills.part_motion.grasp_part`, the sub-task and its joint); every ``reset`` picks one
with the env's seeded ``np_random``. With one start it is the learn stage's fine-tuning env; with the
starts of many built scenes it is the warm start's training env (``benchmarks/train_warm_start.py``),
which is how one policy learns knobs of ovens, toasters, microwaves and washing machines and the push
buttons of coffee machines at once. The observation is :class:`~anomalygen.skills.part_motion.PartReadout`'s
(17 numbers, relative to cup and part); the reward is the sub-task's RewardSpec through
:class:`~anomalygen.skills.learned.subtask_env.SubTaskReadout`; success (``info["is_success"]``, which also ends the
episode) is the joint within ``CLOSED_TOL`` of its travel from off, as ``joint_closed`` counts it.

Settings as every SAC env here (:mod:`~anomalygen.skills.learned.subtask_env`): 7-D action through
``Agent.apply_action`` (the agent's 3 cm, 0.1 rad per step, suction flag), frameskip 2 (the lead's,
``part_motion.FRAMESKIP``); episodes of 60 steps (the scripted reference turns a knob from 90 % on to
off in 15-26 steps), set by the registration's ``max_episode_steps`` (``PART_ENV_ID``,
:func:`make_part_env`), +-5 mm noise on the cup target at reset.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from anomalygen.schema import SceneSpec, SubTask
from anomalygen.skills.learned.subtask_env import SubTaskReadout, registered_horizon
from anomalygen.skills.part_motion import FRAMESKIP, OBS_DIM, PartReadout

PART_ENV_ID = "anomalygen/PartTurn-v0"
HORIZON = 60  # control steps per episode: the registered TimeLimit
START_NOISE = 0.005  # m: the cup already holds the part; a bigger jump would tear the hold


@dataclass
class PartStart:
    """Where one episode of the family starts: a scene and a snapshot with the part held."""

    model: object
    snapshot: np.ndarray
    spec: SceneSpec
    sub_task: SubTask
    bindings: dict
    joint: str
    closed: float
    far: float


class _Loaded:
    """One start made ready: own model copy (suction writes eq_data), own data, both readouts."""

    def __init__(self, s: PartStart):
        import mujoco

        self.model = copy.deepcopy(s.model)
        self.data = mujoco.MjData(self.model)
        self.snapshot = np.array(s.snapshot, dtype=float, copy=True)
        self.eq0 = self.model.eq_data.copy()
        self.part = PartReadout(self.model, s.joint, s.closed, s.far)
        self.task = SubTaskReadout(self.model, s.spec, s.sub_task, s.bindings)

    def restore(self) -> None:
        import mujoco

        self.model.eq_data[:] = self.eq0
        mujoco.mj_setState(self.model, self.data, self.snapshot, mujoco.mjtState.mjSTATE_INTEGRATION)
        mujoco.mj_forward(self.model, self.data)


def part_control_step(loaded, action, t: int, advance, horizon: int = HORIZON) -> tuple[float, bool]:
    """One control step, shared by the env and the replay on the Driver: apply the action, advance
    the physics, return (reward, success)."""
    a = loaded.part.agent.apply_action(loaded.data, action)
    advance()
    state = loaded.task.state(loaded.model, loaded.data, a)
    return float(loaded.task.reward_of(state)), loaded.part.at_off(loaded.data)


class PartTurnEnv(gym.Env):
    """Turn a held part to off; one of ``starts`` per episode (see the module docstring). Make it with
    :func:`make_part_env` (``gym.make``), which adds the episode's TimeLimit."""

    metadata = {"render_modes": []}

    def __init__(self, starts: list[PartStart], *, start_noise: float = START_NOISE):
        if not starts:
            raise ValueError("PartTurnEnv needs at least one start")
        self._loaded = [_Loaded(s) for s in starts]
        self.start_noise = float(start_noise)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(7,), dtype=np.float32)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(OBS_DIM,), dtype=np.float64)
        self._cur = self._loaded[0]
        self._t = 0

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        k = int(self.np_random.integers(len(self._loaded))) if len(self._loaded) > 1 else 0
        self._cur = cur = self._loaded[k]
        cur.restore()
        if self.start_noise > 0:
            cur.data.mocap_pos[cur.part.agent.mocap] += self.np_random.uniform(-self.start_noise, self.start_noise, 3)
        self._t = 0
        return cur.part.observation(cur.model, cur.data, 0, self.horizon), {"start": k}

    def step(self, action):
        import mujoco

        cur = self._cur

        def advance() -> None:
            for _ in range(FRAMESKIP):
                mujoco.mj_step(cur.model, cur.data)

        self._t += 1
        reward, ok = part_control_step(cur, action, self._t, advance, self.horizon)
        obs = cur.part.observation(cur.model, cur.data, self._t, self.horizon)
        return obs, reward, ok, False, {"success": ok, "is_success": ok}

    @property
    def horizon(self) -> int:
        """Episode length (``registered_horizon``); the observation's time fraction reads it."""
        return registered_horizon(self, HORIZON)

    def close(self) -> None:
        for ld in self._loaded:
            ld.task.close()


def make_part_env(starts: list[PartStart], **kwargs) -> gym.Env:
    """``gym.make(PART_ENV_ID, starts=...)``: the env inside the TimeLimit its registration sets."""
    return gym.make(PART_ENV_ID, starts=starts, **kwargs)


def register() -> None:
    """Register ``anomalygen/PartTurn-v0`` (idempotent), episodes of ``HORIZON`` steps."""
    if PART_ENV_ID not in gym.registry:
        gym.register(id=PART_ENV_ID, entry_point="anomalygen.skills.learned.part_env:PartTurnEnv",
                     max_episode_steps=HORIZON)


register()
