"""Benchmark: SAC learns to close a cabinet door from a random start (test scene, paper settings).

Acceptance: >= 80% success (deterministic evaluation episodes) within a budget that runs <= 20 min on
2 cores. Prints the learning curve while it runs and one JSON summary line last; ``--out`` also
writes the curve as JSON. ``--stop-at`` ends the run early once an evaluation reaches that success
rate (the acceptance question is "how many steps to 80 %", not "what after N steps").

    nice -n 5 .venv/bin/python benchmarks/bench_sac.py --steps 12000 --out /tmp/bench_sac.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))  # the door env is test support


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--steps", type=int, default=12000)
    ap.add_argument("--eval-every", type=int, default=1000)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--stop-at", type=float, default=0.9)
    ap.add_argument("--eval-episodes", type=int, default=10)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=None)
    args = ap.parse_args()

    from anomalygen.skills.learned.sac import train_sac
    from support.door_env import make_door_env

    t0 = time.perf_counter()
    _, res = train_sac(make_door_env, args.steps, seed=args.seed, eval_every=args.eval_every,
                       eval_episodes=args.eval_episodes, threads=args.threads, stop_at=args.stop_at,
                       log=lambda s: print(s, flush=True))
    first80 = next((c["step"] for c in res.curve if c["success"] >= 0.8), None)
    summary = {"task": "close cabinet door (door 0.5-1.3 rad open, cup starts near the handle)",
               "steps": res.steps, "budget": args.steps, "steps_to_80": first80,
               "best_success": res.best_success, "best_step": res.best_step, "wall_s": time.perf_counter() - t0,
               "curve": res.curve, "passed": res.best_success >= 0.8}
    print(json.dumps({k: v for k, v in summary.items() if k != "curve"}))
    if args.out:
        with open(args.out, "w") as fh:
            json.dump(summary, fh, indent=2)


if __name__ == "__main__":
    main()
