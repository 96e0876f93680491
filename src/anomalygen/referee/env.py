"""``JudgedEnv``: any scene env, judged by the referee when the caller asks.

Why: a researcher's own policy must be judged exactly like ours. The wrapped env is the perception-only
scene env (it knows nothing of the answer key); the referee (:func:`anomalygen.referee.judge`) gives
the verdict on the state the policy left — on copies, after releasing what the cup holds and letting
the scene settle. That costs 20-60 ms, several hundred physics steps' worth, so it happens only when
the caller asks, by the ``judging`` mode:

- ``"end"`` (the default of :func:`anomalygen.make_env`, for outside policies): when an episode
  terminates or is truncated, ``info["verdict"]`` holds the :class:`~anomalygen.schema.Verdict` and
  ``info["is_success"]`` is ``verdict.resolved``, as Stable-Baselines3's callbacks read it; the env's
  own success check, if it had one, stays beside it as ``info["own_check"]``. Before the end,
  ``info`` is the env's own.
- ``"never"`` (for training loops, and the default of :func:`anomalygen.make_vec_env`): ``step``
  passes the env's own results through untouched, at the end too; no referee is called unless the
  caller asks for a verdict with :meth:`JudgedEnv.verdict_now`.

``judging`` is a plain attribute: an evaluation env may switch it on and off between episodes (through
a vector env: ``venv.set_attr("judging", "end")``).
"""

from __future__ import annotations

import functools
from pathlib import Path

import gymnasium as gym

#: the judging modes; ``True`` reads as "end", ``False`` and ``None`` as "never"
JUDGING = ("end", "never")


def judging_mode(judge) -> str:
    """``"end"`` or ``"never"`` from what a caller may pass as ``judge``."""
    if judge is True or judge == "end":
        return "end"
    if judge is False or judge is None or judge == "never":
        return "never"
    raise ValueError(f"judge={judge!r}: choose one of {JUDGING} (or True / False)")


class JudgedEnv(gym.Wrapper):
    """Adds the referee's verdict to ``info`` at the end of every episode (``judging="end"``), or only
    on demand (``judging="never"``: :meth:`verdict_now`)."""

    def __init__(self, env: gym.Env, scene_dir: str | Path | None = None, *, judge="end"):
        super().__init__(env)
        self.scene_dir = Path(scene_dir if scene_dir is not None else env.unwrapped.scene_dir)
        self.judging = judge
        self.verdict = None  # the last verdict of this episode (at its end, or asked for)

    @property
    def judging(self) -> str:
        """When the referee judges: "end" or "never" (settable, also as True / False)."""
        return self._judging

    @judging.setter
    def judging(self, judge) -> None:
        self._judging = judging_mode(judge)
        # Judging off: ``step`` is the wrapped env's own bound method, so the wrapper adds no call
        # per step (benchmarks/bench_env_step.py); judging at the end: this class's step.
        self.step = self.env.step if self._judging == "never" else self._judged_step

    def reset(self, **kwargs):
        self.verdict = None
        return self.env.reset(**kwargs)

    def step(self, action):
        return self._judged_step(action) if self._judging == "end" else self.env.step(action)

    def _judged_step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        if terminated or truncated:
            verdict = self.verdict_now()
            info = {**info, "own_check": info.get("is_success"), "verdict": verdict,
                    "is_success": verdict.resolved}
        return obs, reward, terminated, truncated, info

    def verdict_now(self):
        """The referee's verdict on the current state (the live episode is left untouched)."""
        from anomalygen.referee.settle import judge

        base = self.env.unwrapped
        self.verdict = judge(self.scene_dir, base.model, base.data)
        return self.verdict


def make_judged_env(scene_dir, *, judge="end", **kwargs) -> JudgedEnv:
    """The bare scene env of ``anomalygen.world.env.make_env(scene_dir, **kwargs)`` in a
    :class:`JudgedEnv` with ``judge`` ("end" / True, or "never" / False)."""
    from anomalygen.world.env import make_env

    mode = judging_mode(judge)  # a wrong mode fails before the scene loads
    return JudgedEnv(make_env(scene_dir, **kwargs), scene_dir, judge=mode)


def make_judged_vec_env(scene_dir, n_envs: int = 1, *, judge="never", subproc: bool = False,
                        seed: int | None = None, **kwargs):
    """A Stable-Baselines3 ``VecEnv`` of ``n_envs`` judged envs of one scene (see :func:`make_judged_env`):
    ``DummyVecEnv`` (one process; the cheaper one on a busy machine), or ``SubprocVecEnv`` with
    ``subproc`` (one spawned process per env, worth it only with free cores; ``kwargs`` must then
    pickle with cloudpickle). ``seed`` seeds the envs' next reset (``seed + i`` for env ``i``)."""
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    n_envs = int(n_envs)
    if n_envs < 1:
        raise ValueError(f"n_envs={n_envs}: at least one env")
    factory = functools.partial(make_judged_env, str(scene_dir), judge=judging_mode(judge), **kwargs)
    fns = [factory] * n_envs
    venv = SubprocVecEnv(fns, start_method="spawn") if subproc else DummyVecEnv(fns)
    if seed is not None:
        venv.seed(seed)
    return venv
