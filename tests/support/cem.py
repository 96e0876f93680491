"""Cross-entropy-method MPC for locomotion sub-tasks, with the simulator as the dynamics model.

As in the paper, no model is learned: the planner copies the current MuJoCo state, rolls candidate
action sequences forward in a batch (``mujoco.rollout``, multi-threaded C), scores them with the
task cost, and refits a Gaussian to the elites. The episode has ``horizon`` control steps (150) of
``frameskip`` physics steps (4); the planner looks ``lookahead`` control steps ahead and re-plans
every ``replan_every`` steps (receding horizon), which is far more robust for a legged robot than
one open-loop plan.

The legged robot is the MuJoCo Ant shipped with Gymnasium (a maintained package, MIT). Test support,
not part of the package: household scenes carry the wheeled arm, so the learn stage reports a CEM
sub-task as not executed; this planner and its Ant test keep the method demonstrated.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


def ant_xml_path() -> Path:
    import gymnasium

    return Path(gymnasium.__file__).parent / "envs" / "mujoco" / "assets" / "ant.xml"


@dataclass
class WalkToGoal:
    """Locomotion task: bring the torso within ``radius`` of ``goal`` (x, y) without falling."""

    goal: tuple[float, float] = (2.0, 0.0)
    radius: float = 0.5
    min_height: float = 0.3  # the torso is lower only when the ant has fallen

    def cost(self, qpos: np.ndarray) -> np.ndarray:
        """Per-step cost for a batch of trajectories: qpos (..., nq) -> (...)."""
        xy = qpos[..., 0:2]
        dist = np.linalg.norm(xy - np.asarray(self.goal), axis=-1)
        qx, qy = qpos[..., 4], qpos[..., 5]
        up = 1.0 - 2.0 * (qx * qx + qy * qy)  # z component of the torso's up axis
        unhealthy = (qpos[..., 2] < self.min_height) | (up < 0.5)
        return dist + 3.0 * unhealthy.astype(float)

    def success(self, qpos: np.ndarray) -> bool:
        return bool(np.linalg.norm(qpos[0:2] - np.asarray(self.goal)) <= self.radius)


@dataclass
class CEMConfig:
    horizon: int = 150
    frameskip: int = 4
    lookahead: int = 30
    knot_every: int = 5  # actions are linear between knots: a smooth, low-dimensional search space
    replan_every: int = 5
    samples: int = 48
    elites: int = 6
    iterations: int = 4
    threads: int = 2
    init_std: float = 0.6
    min_std: float = 0.05


@dataclass
class CEMResult:
    success: bool
    steps: int
    final_distance: float
    wall_s: float
    costs: list[float] = field(default_factory=list)
    qpos_trace: list[list[float]] = field(default_factory=list)


def _qpos_slice(model) -> slice:
    import mujoco

    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    # FULLPHYSICS starts with time (1 number), then qpos.
    assert mujoco.mj_stateSize(model, mujoco.mjtState.mjSTATE_TIME) == 1
    del spec
    return slice(1, 1 + model.nq)


def _knots_to_actions(knots: np.ndarray, cfg: CEMConfig) -> np.ndarray:
    """(..., n_knots, nu) -> (..., lookahead, nu) by linear interpolation."""
    n_knots = knots.shape[-2]
    t = np.linspace(0, n_knots - 1, cfg.lookahead)
    i0 = np.minimum(np.floor(t).astype(int), n_knots - 2)
    w = (t - i0)[:, None]
    return knots[..., i0, :] * (1 - w) + knots[..., i0 + 1, :] * w


def n_knots(cfg: CEMConfig) -> int:
    return cfg.lookahead // cfg.knot_every + 1


def cem_plan(model, datas, task: WalkToGoal, cfg: CEMConfig, rng: np.random.Generator, mean: np.ndarray) -> np.ndarray:
    """Refine a knot-sequence mean (n_knots x nu) by CEM from the state of ``datas[0]``."""
    import mujoco
    from mujoco import rollout

    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.zeros(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, datas[0], state0, spec)
    lo, hi = model.actuator_ctrlrange[:, 0], model.actuator_ctrlrange[:, 1]
    std = np.full_like(mean, cfg.init_std)
    qs = _qpos_slice(model)
    best, best_cost = mean, np.inf
    for _ in range(cfg.iterations):
        seqs = np.clip(mean + std * rng.standard_normal((cfg.samples, *mean.shape)), lo, hi)
        seqs[0] = np.clip(mean, lo, hi)  # keep the incumbent
        controls = np.repeat(_knots_to_actions(seqs, cfg), cfg.frameskip, axis=1)
        states, _ = rollout.rollout(model, datas[1:] or datas[:1], state0[None, :], controls)
        qpos = states[:, cfg.frameskip - 1 :: cfg.frameskip, qs]
        weights = np.linspace(0.5, 1.0, qpos.shape[1])  # the end of the lookahead matters most
        costs = (task.cost(qpos) * weights).sum(axis=1)
        elite = seqs[np.argsort(costs)[: cfg.elites]]
        mean = elite.mean(axis=0)
        std = np.maximum(elite.std(axis=0), cfg.min_std)
        if costs.min() < best_cost:
            best_cost, best = float(costs.min()), seqs[int(np.argmin(costs))]
    return best


def run_cem(task: WalkToGoal, cfg: CEMConfig, rng: np.random.Generator, *, model=None, on_step=None) -> CEMResult:
    """Execute the locomotion task by receding-horizon CEM in the Ant model; stop at success."""
    import mujoco

    t0 = time.perf_counter()
    model = model or mujoco.MjModel.from_xml_path(str(ant_xml_path()))
    data = mujoco.MjData(model)
    workers = [mujoco.MjData(model) for _ in range(max(1, cfg.threads))]
    mujoco.mj_resetData(model, data)
    data.qpos[:] = model.qpos0 + rng.uniform(-0.05, 0.05, model.nq) * np.r_[0, 0, 0, np.zeros(4), np.ones(model.nq - 7)]
    mujoco.mj_forward(model, data)
    mean = np.zeros((n_knots(cfg), model.nu))
    result = CEMResult(success=False, steps=0, final_distance=np.inf, wall_s=0.0)
    plan = mean
    for step in range(cfg.horizon):
        k = step % cfg.replan_every
        if k == 0:
            knots = cem_plan(model, [data, *workers], task, cfg, rng, mean)
            plan = _knots_to_actions(knots, cfg)
            # warm start: shift the knots by the time we will execute before re-planning
            shift = max(1, cfg.replan_every // cfg.knot_every)
            mean = np.concatenate([knots[shift:], np.repeat(knots[-1:], shift, axis=0)])
        data.ctrl[:] = plan[k]
        for _ in range(cfg.frameskip):
            mujoco.mj_step(model, data)
        result.steps = step + 1
        result.costs.append(float(task.cost(data.qpos[None])[0]))
        result.qpos_trace.append(data.qpos.tolist())
        if on_step is not None:
            on_step(model, data)
        if task.success(data.qpos):
            result.success = True
            break
    result.final_distance = float(np.linalg.norm(data.qpos[:2] - np.asarray(task.goal)))
    result.wall_s = time.perf_counter() - t0
    return result
