"""``JudgedEnv``: any scene env, judged by the referee when its episode ends.

Why: a researcher's own policy must be judged exactly like ours. The wrapped env is the perception-only
scene env (it knows nothing of the answer key); when an episode terminates or is truncated, this
wrapper asks the referee (:func:`anomalygen.referee.judge`) for the verdict on the state the policy
left — on copies, after releasing what the cup holds and letting the scene settle — and puts it in
``info["verdict"]`` (a :class:`~anomalygen.schema.Verdict`) with ``info["is_success"] =
verdict.resolved``, as Stable-Baselines3's callbacks read it. The env's own success check, if it had
one, stays beside it as ``info["own_check"]``. Before the end, ``info`` is the env's own.
"""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym


class JudgedEnv(gym.Wrapper):
    """Adds the referee's verdict to ``info`` at the end of every episode of a built scene's env."""

    def __init__(self, env: gym.Env, scene_dir: str | Path | None = None):
        super().__init__(env)
        self.scene_dir = Path(scene_dir if scene_dir is not None else env.unwrapped.scene_dir)
        self.verdict = None  # the last episode's verdict

    def reset(self, **kwargs):
        self.verdict = None
        return self.env.reset(**kwargs)

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        if terminated or truncated:
            from anomalygen.referee.settle import judge

            base = self.env.unwrapped
            self.verdict = judge(self.scene_dir, base.model, base.data)
            info = {**info, "own_check": info.get("is_success"), "verdict": self.verdict,
                    "is_success": self.verdict.resolved}
        return obs, reward, terminated, truncated, info
