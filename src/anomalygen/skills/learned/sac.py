"""SAC with the paper's settings, keeping the checkpoint with the best *success rate*.

RoboGen keeps the checkpoint with the best return, which rewards shaping artefacts (hovering near a
handle scores well without ever closing the door). We evaluate deterministic episodes periodically
and keep the policy whose success rate is highest (ties broken by return).
Settings: 3x256 MLPs for actor and critics, learning rate 3e-4 for actor, critic and entropy
coefficient (SB3 uses the same rate for all three), one gradient step per env step after a short
(500-step) random warm-up. Torch threads default to ONE: on a loaded 2-core machine two OpenMP
threads spin against each other (figures in docs/learn.md); pass ``threads=2`` on a quiet machine. The entropy coefficient is
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
    """(success rate, mean return) of deterministic episodes; success is the final step's
    ``info["is_success"]`` (Gymnasium's and SB3's key; every env here sets it)."""
    succ, rets = [], []
    for k in range(episodes):
        obs, _ = env.reset(seed=seed + k)
        ret, done, info = 0.0, False, {}
        while not done:
            act, _ = model.predict(obs, deterministic=True)
            obs, r, term, trunc, info = env.step(act)
            ret += r
            done = term or trunc
        succ.append(bool(info.get("is_success")))
        rets.append(ret)
    return float(np.mean(succ)), float(np.mean(rets))


def success_eval_callback(eval_env, *, eval_every: int, episodes: int, seed: int, result: SACResult,
                          stop_at: float | None, log=None):
    """A periodic evaluation that keeps the best model by success rate instead of by return.

    It replaces ``EvalCallback``'s behaviour (seeded episodes on the env itself, the best checkpoint
    kept in memory by success, early stop), so it is a ``BaseCallback`` of its own rather than an
    ``EvalCallback`` with its insides overridden. Built inside a function because stable-baselines3 is
    imported lazily. Evaluation episodes are seeded (``seed + k``), so every evaluation of a run sees
    the same starts and two checkpoints are compared on equal terms; success is the episodes' final
    ``info["is_success"]``. The rate and mean return go to the SB3 logger as ``eval/success_rate``
    and ``eval/mean_reward``, as ``EvalCallback`` names them.
    """
    from stable_baselines3.common.callbacks import BaseCallback

    class SuccessEvalCallback(BaseCallback):
        def __init__(self):
            super().__init__(verbose=0)
            self.eval_env, self.eval_freq = eval_env, eval_every
            self.best_success, self.best_mean_reward, self.t0 = -1.0, -np.inf, time.perf_counter()

        def evaluate(self, step: int) -> None:
            s, r = evaluate_policy(self.model, self.eval_env, episodes, seed=seed)
            self.logger.record("eval/mean_reward", r)
            self.logger.record("eval/success_rate", s)
            result.curve.append({"step": step, "success": s, "return": r, "wall_s": time.perf_counter() - self.t0})
            if log:
                log(f"step {step}: success {s:.2f} return {r:.1f}")
            if (s, r) > (self.best_success, self.best_mean_reward):
                self.best_success, self.best_mean_reward = s, r
                result.best_success, result.best_return, result.best_step = s, r, step
                result.policy_state = copy.deepcopy(self.model.policy.state_dict())

        def _on_step(self) -> bool:
            # with n vectorised envs num_timesteps grows by n per call: evaluate when it crosses a multiple
            n = self.training_env.num_envs if self.training_env is not None else 1
            if self.eval_freq > 0 and self.num_timesteps // self.eval_freq != (self.num_timesteps - n) // self.eval_freq:
                self.evaluate(self.num_timesteps)
                if stop_at is not None and result.curve[-1]["success"] >= stop_at:
                    result.steps = self.num_timesteps
                    return False
            return True

    return SuccessEvalCallback()


def train_sac(make_env, steps: int, *, seed: int = 0, eval_every: int = 1000, eval_episodes: int = 5,
              learning_starts: int = 500, threads: int = 1, stop_at: float | None = None, ent_coef: str = "auto_0.1",
              learning_rate: float = 3e-4, net_arch: tuple[int, ...] = (256, 256, 256), batch_size: int = 256,
              train_freq: int = 1, gradient_steps: int = 1, log=None, n_envs: int = 1, subproc: bool = False,
              init_model: str | None = None, eval_env=None, pretrain=None) -> tuple[object, SACResult]:
    """Train SAC for ``steps`` env steps; return the model loaded with the best-success checkpoint.

    The defaults are the paper's settings (module docstring). With ``stop_at``, training ends at the
    first evaluation whose success rate reaches it (``result.steps`` is then the steps actually taken);
    a warm start (``init_model``, an SB3 zip) whose step-0 evaluation already reaches it is returned
    untrained. ``n_envs`` > 1 collects experience from that many envs at once (SB3 ``DummyVecEnv``, or
    ``SubprocVecEnv`` with ``subproc``: one process per env, worth it only with free cores, and
    ``make_env`` must then pickle); ``steps`` counts the transitions of all envs together. Evaluation
    runs on one more env from ``make_env`` (or ``eval_env``: held-out scenes). ``pretrain(model)``
    runs before the step-0 evaluation (e.g. :func:`behaviour_clone`, demonstrations in the buffer).
    """
    import torch
    from stable_baselines3 import SAC
    from stable_baselines3.common.utils import configure_logger
    from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv

    torch.set_num_threads(threads)
    n_envs = max(1, int(n_envs))
    if n_envs == 1:
        env = make_env()
    elif subproc:
        env = SubprocVecEnv([make_env] * n_envs, start_method="spawn")
    else:
        env = DummyVecEnv([make_env] * n_envs)
    eval_env = eval_env if eval_env is not None else make_env()
    # SB3 makes one call to train() per n_envs transitions: keep one gradient step per transition
    gradient_steps = gradient_steps * n_envs
    starts = min(learning_starts, max(1, steps // 4))
    if init_model is not None:
        # a warm start keeps its weights and entropy coefficient; its replay buffer starts empty, so a
        # short warm-up (at most 100 steps, SB3's uniform actions) fills it before the first update
        model = SAC.load(init_model, env=env, device="cpu", learning_starts=min(starts, 100), seed=seed,
                         learning_rate=learning_rate, batch_size=batch_size, train_freq=train_freq,
                         gradient_steps=gradient_steps)
    else:
        model = SAC("MlpPolicy", env, learning_rate=learning_rate, policy_kwargs={"net_arch": list(net_arch)},
                    learning_starts=starts, batch_size=batch_size, train_freq=train_freq,
                    gradient_steps=gradient_steps, ent_coef=ent_coef, seed=seed, verbose=0, device="cpu")
    model.set_logger(configure_logger(verbose=0))  # the logger learn() would make, ready for the step-0 evaluation
    result = SACResult(best_success=-1.0, best_return=-np.inf, best_step=0, steps=steps, wall_s=0.0)
    callback = success_eval_callback(eval_env, eval_every=eval_every, episodes=eval_episodes,
                                     seed=10_000 + seed * 100, result=result, stop_at=stop_at, log=log)
    callback.init_callback(model)
    if pretrain is not None:
        pretrain(model)
    callback.evaluate(0)
    if init_model is not None and stop_at is not None and result.curve[0]["success"] >= stop_at:
        result.steps = 0
    elif steps > 0:
        model.learn(total_timesteps=steps, callback=callback)
    if result.curve[-1]["step"] != result.steps:
        callback.evaluate(result.steps)
    if result.policy_state is not None:
        model.policy.load_state_dict(result.policy_state)
    result.wall_s = time.perf_counter() - callback.t0
    return model, result


def behaviour_clone(model, obs: np.ndarray, actions: np.ndarray, *, steps: int = 2000, batch_size: int = 256,
                    seed: int = 0) -> float:
    """Pre-train a SAC actor on demonstrations: maximise the log-likelihood of the demonstrated
    actions under the squashed Gaussian policy (so the spread shrinks too, not only the mean).

    Why: a suction hold is lost by any step whose last action entry is <= 0, so a freshly initialised
    policy (half its steps release) rarely keeps a knob long enough to learn from it; starting SAC
    from a policy that holds and turns makes its data informative from the first episode. Actions are
    clipped to +-0.97 (tanh never reaches 1). Returns the final mean negative log-likelihood.
    """
    import torch

    rng = np.random.default_rng(seed)
    x = torch.as_tensor(obs, dtype=torch.float32)
    y = torch.as_tensor(np.clip(actions, -0.97, 0.97), dtype=torch.float32)
    actor = model.actor
    opt = torch.optim.Adam(actor.parameters(), lr=1e-3)
    loss_v = float("nan")
    for _ in range(steps):
        idx = torch.as_tensor(rng.integers(0, len(x), size=min(batch_size, len(x))))
        mean, log_std, _ = actor.get_action_dist_params(x[idx])
        dist = actor.action_dist.proba_distribution(mean, log_std)
        loss = -dist.log_prob(y[idx]).mean()
        opt.zero_grad()
        loss.backward()
        opt.step()
        loss_v = float(loss.detach())
    return loss_v
