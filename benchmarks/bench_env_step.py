"""Per-step cost of the low-level env (issue 40, point 5); prints one JSON object.

Four ways to run the same episodes of zero-action steps on one built scene (``horizon`` steps each,
``frameskip`` physics steps per control step), timed step calls only (resets are untimed, the same
for all four):

* ``raw``: ``mujoco.mj_step(model, data, frameskip)`` on the bare env's own model and data after the
  env's reset (a zero action leaves the mocap target where the reset put it, so this is the same
  physics the envs simulate);
* ``bare``: the bare ``SceneEnv`` (``anomalygen.world.env.make_env``);
* ``judge_never``: ``anomalygen.make_env(scene, judge="never")``, what a training loop uses;
* ``judge_end``: ``anomalygen.make_env(scene)``, the referee judging at every episode's end.

They run interleaved episode by episode, in a rotating order, in two phases per round (``raw``,
``bare`` and ``judge_never``; then ``raw`` again beside ``judge_end``, so the referee's work never
runs between the first phase's episodes), ``rounds`` times. Each round's ratios to its phase's
``raw`` are taken within the round, so machine load hits every side alike; the medians over rounds
are reported, by two clocks: ``wall`` (``perf_counter``) and ``cpu`` (this thread's CPU time,
``thread_time``: on a machine shared with other jobs it leaves out the time spent waiting for a
core). The acceptance bound: ``judge_never`` at most 1.3x ``raw`` (``meets_target``: by both clocks).

Usage: ``python benchmarks/bench_env_step.py [--scene DIR] [--steps 1000] [--horizon 100] [--rounds 9]``
(without ``--scene`` it builds the knife-on-counter scene of ``bench_scene.py`` in a temp folder).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("HF_HUB_OFFLINE", "1")

TARGET_RATIO = 1.3  # issue 40: judging off costs at most 1.3x the raw mj_step calls per step
VARIANTS = ("raw", "bare", "judge_never", "judge_end")
RAW_BESIDE_JUDGING = "raw_beside_judge_end"
# Two phases per round, each interleaving its variants episode by episode: the referee's settling
# (~16 ms of other code and memory) would otherwise run between the first phase's episodes, which no
# training loop with judging off does. Each phase has its own raw episodes (named as given).
PHASES = ((("raw", "bare", "judge_never"), "raw"), (("raw", "judge_end"), RAW_BESIDE_JUDGING))


def build_scene(out: Path) -> Path:
    """bench_scene.py's knife-on-counter task (robot, furniture and objects), built at seed 2."""
    from bench_scene import _task

    from anomalygen.config import Settings
    from anomalygen.scene.build import build_scene as build

    build(_task(2), seed=2, settings=Settings(), out_dir=out)
    return out


def _episode(step, reset, n: int) -> tuple[float, float]:
    """Wall and CPU seconds (this thread's) spent in ``n`` calls of ``step`` after an untimed ``reset``."""
    reset()
    w, c = time.perf_counter(), time.thread_time()
    for _ in range(n):
        step()
    return time.perf_counter() - w, time.thread_time() - c


def bench(scene: Path, steps: int, horizon: int, rounds: int, frameskip: int = 2) -> dict:
    import mujoco
    import numpy as np

    import anomalygen
    from anomalygen.world.env import make_env

    envs = {
        "bare": make_env(scene, frameskip=frameskip, horizon=horizon),
        "judge_never": anomalygen.make_env(scene, judge="never", frameskip=frameskip, horizon=horizon),
        "judge_end": anomalygen.make_env(scene, frameskip=frameskip, horizon=horizon),
    }
    zero = np.zeros(7, dtype=np.float32)
    raw_env = envs["bare"]
    m, d = raw_env.model, raw_env.data
    runs = {
        "raw": (lambda: mujoco.mj_step(m, d, frameskip), lambda: raw_env.reset(seed=0)),
        **{k: ((lambda e=e: e.step(zero)), (lambda e=e: e.reset(seed=0))) for k, e in envs.items()},
    }
    for step, reset in runs.values():  # warm-up: first calls, the referee's imports and caches
        _episode(step, reset, horizon)
    lengths = [min(horizon, steps - s) for s in range(0, steps, horizon)]
    per_step = {clock: {k: [] for k in (*VARIANTS, RAW_BESIDE_JUDGING)} for clock in ("wall", "cpu")}
    for _ in range(rounds):
        for phase, raw_as in PHASES:
            total = {clock: dict.fromkeys(phase, 0.0) for clock in per_step}
            for i, n in enumerate(lengths):  # episode by episode, in a rotating order: load drifts slower
                for k in phase[i % len(phase):] + phase[:i % len(phase)]:
                    wall, cpu = _episode(*runs[k], n)
                    total["wall"][k] += wall
                    total["cpu"][k] += cpu
            for clock, t in total.items():
                for k in phase:
                    per_step[clock][raw_as if k == "raw" else k].append(1e6 * t[k] / steps)
    for e in envs.values():
        e.close()
    out = {"frameskip": frameskip, "steps_per_round": steps, "horizon": horizon, "rounds": rounds}
    for clock, us in per_step.items():
        base = {"bare": "raw", "judge_never": "raw", "judge_end": RAW_BESIDE_JUDGING}
        ratios = {k: [v / r for v, r in zip(us[k], us[b], strict=True)] for k, b in base.items()}
        judge_ms = [(e - n) * steps / len(lengths) / 1e3 for e, n in zip(us["judge_end"], us["judge_never"], strict=True)]
        out[clock] = {
            "step_us_median": {k: round(statistics.median(v), 1) for k, v in us.items()},
            "ratio_to_raw_median": {k: round(statistics.median(v), 3) for k, v in ratios.items()},
            "ratio_to_raw_max": {k: round(max(v), 3) for k, v in ratios.items()},
            "judging_ms_per_episode_median": round(statistics.median(judge_ms), 1),
        }
    out["target_ratio_judge_never"] = TARGET_RATIO
    out["meets_target"] = all(out[c]["ratio_to_raw_median"]["judge_never"] <= TARGET_RATIO for c in per_step)
    return out


def _commit() -> str:
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              cwd=Path(__file__).parent).stdout.strip()
    except OSError:
        return ""


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", type=Path, help="a built scene folder (default: build one)")
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--horizon", type=int, default=100)
    ap.add_argument("--rounds", type=int, default=9)
    args = ap.parse_args(argv)
    scene = args.scene or build_scene(Path(tempfile.mkdtemp(prefix="bench-env-step-")) / "scene")
    result = {
        "env_step": bench(scene, args.steps, args.horizon, args.rounds),
        "scene": str(scene),
        "machine": f"{os.cpu_count()} cpu",
        "load_avg": round(os.getloadavg()[0], 2),
        "commit": _commit(),
    }
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
