"""Scene-stage benchmarks; prints one JSON object.

* ``build_scenes_per_min``: build + settle + validate + render + write of knowledge-engine-style tasks
  (a fixed mix of placements), in one process after warm-up (SBERT and mesh loading excluded, as the
  issue excludes LLM time); ``x2 cores`` extrapolates to the stage's 2 worker processes.
* ``env``: ``env.step`` time over raw ``mj_step(model, data, frameskip)`` on the same model, measured
  in one run as interleaved blocks (median ratio), so machine load hits both sides alike. The raw
  loop replays the mocap targets the env produced, so both sides simulate the same motion (a static
  arm is cheaper to simulate than a moving one, which is not the env's overhead).

Usage: ``python benchmarks/bench_scene.py [--scenes N] [--steps N]``
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("HF_HUB_OFFLINE", "1")

TASKS = [
    ("remove_choking_hazards", "Safe", "button_battery", "floor", []),
    ("close_open_refrigerator", "Refrigerator", "Refrigerator", "floor", [("Refrigerator", "door", "open")]),
    ("store_sharp_objects", "Table", "kitchen_knife", "counter_edge", []),
    ("secure_medications", "StorageFurniture", "pill_bottle", "inside:StorageFurniture", []),
    ("move_fragile_from_edge", "Table", "vase", "table_edge", []),
    ("reduce_tripping_hazards", "Chair", "shoe", "walkway", []),
]


def _task(i: int):
    from anomalygen.schema import TaskProposal

    hc, target, hazard, placement, arts = TASKS[i % len(TASKS)]
    return TaskProposal(
        id=f"bench-{i:03d}",
        name=f"bench {i}",
        explanation="benchmark",
        description=f"A {hazard} at {placement}.",
        category="household_hazard",
        hazard_class=hc,
        target_asset=target,
        scenario=dict(hazard_object=hazard, room="kitchen", placement=placement),
        articulations=[dict(object=o, part=p, initial_state=s) for o, p, s in arts],
        provenance=dict(engine="knowledge", mode="brainstorm"),
    )


def bench_build(n: int) -> dict:
    import torch

    from anomalygen.config import Settings
    from anomalygen.errors import ItemFailed
    from anomalygen.scene.build import build_scene

    torch.set_num_threads(1)  # as the build stage's workers do (scene/stage.py)
    settings = Settings()
    out = Path(tempfile.mkdtemp(prefix="bench-scene-"))
    build_scene(_task(0), seed=99, settings=settings, out_dir=out / "warmup")  # SBERT + meshes + GL
    ok = failed = 0
    t0 = time.perf_counter()
    for i in range(n):
        try:
            build_scene(_task(i), seed=i, settings=settings, out_dir=out / f"s{i}")
            ok += 1
        except ItemFailed:
            failed += 1
    wall = time.perf_counter() - t0
    per_min = 60.0 * n / wall
    return {
        "scenes": n,
        "valid": ok,
        "failed": failed,
        "wall_s": round(wall, 2),
        "scenes_per_min_1_core": round(per_min, 1),
        "scenes_per_min_2_workers_est": round(2 * per_min, 1),
        "scene_dir": str(out),
    }


def bench_env(scene_dir: Path, steps: int, frameskip: int = 2, blocks: int = 9) -> dict:
    """Interleaved blocks: env.step with random actions vs raw mj_step replaying the same mocap
    trajectory (the physics then does identical work: same arm motion, same contacts)."""
    import mujoco
    import numpy as np

    from anomalygen.world.env import make_env

    env = make_env(scene_dir, frameskip=frameskip, horizon=10**9)  # the bare env: its own step cost
    rng = np.random.default_rng(0)
    actions = rng.uniform(-0.5, 0.5, size=(steps, 7))
    actions[:, 6] = -1.0
    # Record the mocap targets the env produces (untimed); the env is deterministic.
    env.reset(seed=0)
    traj_pos, traj_quat = np.zeros((steps, 3)), np.zeros((steps, 4))
    for i, a in enumerate(actions):
        env.step(a)
        traj_pos[i], traj_quat[i] = env.data.mocap_pos[0], env.data.mocap_quat[0]
    ratios, env_us, raw_us = [], [], []
    m, d = env.model, env.data
    for _ in range(blocks):
        env.reset(seed=0)
        t = time.perf_counter()
        for a in actions:
            env.step(a)
        te = time.perf_counter() - t
        env.reset(seed=0)
        mpos, mquat = d.mocap_pos, d.mocap_quat
        t = time.perf_counter()
        for i in range(steps):
            mpos[0] = traj_pos[i]
            mquat[0] = traj_quat[i]
            mujoco.mj_step(m, d, frameskip)
        tr = time.perf_counter() - t
        ratios.append(te / tr)
        env_us.append(1e6 * te / steps)
        raw_us.append(1e6 * tr / steps)
    env.reset(seed=0)
    env.frameskip = 0  # Python cost of one step alone
    t = time.perf_counter()
    for a in actions:
        env.step(a)
    python_us = 1e6 * (time.perf_counter() - t) / steps
    env.close()
    return {
        "frameskip": frameskip,
        "steps_per_block": steps,
        "blocks": blocks,
        "env_step_us_median": round(statistics.median(env_us), 1),
        "raw_mj_step_us_median": round(statistics.median(raw_us), 1),
        "overhead_ratio_median": round(statistics.median(ratios), 3),
        "overhead_ratio_max": round(max(ratios), 3),
        "python_only_step_us": round(python_us, 1),
        "target_ratio": 1.2,
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", type=int, default=12)
    ap.add_argument("--steps", type=int, default=1000)
    args = ap.parse_args(argv)
    build = bench_build(args.scenes)
    scene = Path(build["scene_dir"]) / "s2"  # the knife-on-counter scene (robot + furniture + objects)
    if not (scene / "scene.json").exists():
        scene = next(p.parent for p in Path(build["scene_dir"]).glob("*/scene.json"))
    result = {
        "build": build,
        "env": bench_env(scene, args.steps),
        "machine": f"{os.cpu_count()} cpu",
        "load_avg": os.getloadavg()[0],
    }
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
