"""SAC with the paper's settings, keeping the checkpoint with the best *success rate*.

RoboGen keeps the checkpoint with the best return, which rewards shaping artefacts (hovering near a
handle scores well without ever closing the door). We evaluate deterministic episodes periodically
and keep the policy whose success rate is highest (ties broken by return).
Settings: 3x256 MLPs for actor and critics, learning rate 3e-4 for actor, critic and entropy
coefficient (SB3 uses the same rate for all three), one gradient step per env step after a short
(500-step) random warm-up. Torch threads default to ONE: on the shared, loaded 2-core machine two
OpenMP threads spin against each other and 40 SAC updates took > 100 s instead of 2.5 s with one
thread (measured 2026-11-21); pass ``threads=2`` on a quiet machine. The entropy coefficient is
auto-tuned (lr 3e-4, as in the paper) but starts at 0.1 instead of SB3's 1.0: at lr 3e-4 log(alpha)
moves ~3e-4 per update, so from 1.0 the entropy bonus (7-D action) drowned the ~2/step shaped reward
for the first several thousand steps of a small budget.
"""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass, field

import numpy as np


@dataclass
class SACResult:
    best_success: float
    best_return: float
    best_step: int
    steps: int
    wall_s: float
    curve: list[dict] = field(default_factory=list)  # {"step", "success", "return"}
    policy_state: dict | None = None


def evaluate_policy(model, env, episodes: int, seed: int) -> tuple[float, float]:
    """(success rate, mean return) of deterministic episodes; success is the final step's flag."""
    succ, rets = [], []
    for k in range(episodes):
        obs, _ = env.reset(seed=seed + k)
        ret, done, info = 0.0, False, {}
        while not done:
            act, _ = model.predict(obs, deterministic=True)
            obs, r, term, trunc, info = env.step(act)
            ret += r
            done = term or trunc
        succ.append(bool(info.get("success")))
        rets.append(ret)
    return float(np.mean(succ)), float(np.mean(rets))


def train_sac(make_env, steps: int, *, seed: int = 0, eval_every: int = 1000, eval_episodes: int = 5,
              learning_starts: int = 500, threads: int = 1, stop_at: float | None = None, ent_coef: str = "auto_0.1",
              log=None) -> tuple[object, SACResult]:
    """Train SAC for ``steps`` env steps; return the model loaded with the best-success checkpoint.

    With ``stop_at``, training ends at the first evaluation whose success rate reaches it
    (``result.steps`` is then the steps actually taken).
    """
    import torch
    from stable_baselines3 import SAC
    from stable_baselines3.common.callbacks import BaseCallback

    torch.set_num_threads(threads)
    env, eval_env = make_env(), make_env()
    model = SAC("MlpPolicy", env, learning_rate=3e-4, policy_kwargs={"net_arch": [256, 256, 256]},
                learning_starts=min(learning_starts, max(1, steps // 4)), batch_size=256, train_freq=1, gradient_steps=1, ent_coef=ent_coef, seed=seed, verbose=0,
                device="cpu")
    t0 = time.perf_counter()
    result = SACResult(best_success=-1.0, best_return=-np.inf, best_step=0, steps=steps, wall_s=0.0)

    def _evaluate(step: int) -> None:
        s, r = evaluate_policy(model, eval_env, eval_episodes, seed=10_000 + seed * 100)
        result.curve.append({"step": step, "success": s, "return": r, "wall_s": time.perf_counter() - t0})
        if log:
            log(f"step {step}: success {s:.2f} return {r:.1f}")
        if (s, r) > (result.best_success, result.best_return):
            result.best_success, result.best_return, result.best_step = s, r, step
            result.policy_state = copy.deepcopy(model.policy.state_dict())

    class _Eval(BaseCallback):
        def _on_step(self) -> bool:
            if self.num_timesteps % eval_every == 0:
                _evaluate(self.num_timesteps)
                if stop_at is not None and result.curve[-1]["success"] >= stop_at:
                    result.steps = self.num_timesteps
                    return False
            return True

    _evaluate(0)
    if steps > 0:
        model.learn(total_timesteps=steps, callback=_Eval())
    if result.curve[-1]["step"] != result.steps:
        _evaluate(result.steps)
    if result.policy_state is not None:
        model.policy.load_state_dict(result.policy_state)
    result.wall_s = time.perf_counter() - t0
    return model, result
