"""Skill success on the knowledge run with oracle plans: the issue's acceptance figure, by class.

Runs the real pipeline through the CLI in a scratch run folder: ``brainstorm --engine knowledge --n N``,
``build``, ``plan``, ``learn --seeds K`` (videos off) and ``judge`` on the tasks of every hazard class (or
only those named by ``--classes``). Prints the table and one JSON line: per class and overall, the
referee's verdict (``verdict.json``: resolved) over all (task, seed) runs, and beside it, labelled, the
robot's own check (``result.json``'s ``success``).

    .venv/bin/python benchmarks/bench_primitives.py [--n 111] [--seeds 3] [--workers 2] [--out DIR]
        [--retries K] [--classes close_toilet_lid,store_sharp_objects]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from anomalygen import procs


def _cli(*args: str, env=None) -> None:
    exe = Path(sys.executable).with_name("anomalygen")
    subprocess.run([str(exe), *args, "--quiet"], check=True, env=env, preexec_fn=procs.end_with_parent)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=111)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=None, help="run folder (default: a temporary one)")
    ap.add_argument("--retries", type=int, default=None, help="learn.retries (closed-loop redos; default: config's)")
    ap.add_argument("--classes", default=None,
                    help="comma-separated hazard classes to run (default: every class in the brainstormed tasks)")
    a = ap.parse_args()
    run = Path(a.out or tempfile.mkdtemp(prefix="bench_primitives_")) / "run"
    # the oracle plans on single-hazard scenes: this figure measures the skills, not detection (that is
    # bench_loop.py), so plans come from the builder's bindings and the judgement mix is off
    env = {**os.environ, "ANOMALYGEN_LEARN__VIDEO": "false", "ANOMALYGEN_PLAN__SOURCE": "ground_truth",
           "ANOMALYGEN_BUILD__HAZARD_FREE": "0", "ANOMALYGEN_BUILD__MULTI_HAZARD": "0",
           "ANOMALYGEN_BUILD__NEAR_MISSES": "0"}
    if a.retries is not None:
        env["ANOMALYGEN_LEARN__RETRIES"] = str(a.retries)
    t0 = time.perf_counter()
    _cli("brainstorm", "--run", str(run), "--engine", "knowledge", "--n", str(a.n), "--seed", str(a.seed))
    tasks = [json.loads(line) for line in (run / "tasks.jsonl").read_text().splitlines() if line.strip()]
    wanted = set(a.classes.split(",")) if a.classes else None
    chosen = [t["id"] for t in tasks if wanted is None or t["hazard_class"] in wanted]
    if not chosen:  # an empty --only would run every task
        present = sorted({t["hazard_class"] for t in tasks})
        print(f"no task of {', '.join(sorted(wanted or []))} in the {a.n} brainstormed tasks; "
              f"classes present: {', '.join(present)}", file=sys.stderr)
        return 2
    only = [x for tid in chosen for x in ("--only", tid)]
    t_build = time.perf_counter()
    _cli("build", "--run", str(run), "--workers", str(a.workers), "--seed", str(a.seed), *only, env=env)
    built = [tid for tid in chosen if (run / "scenes" / tid / "scene.json").is_file()]
    only = [x for tid in built for x in ("--only", tid)]
    _cli("plan", "--run", str(run), *only, env=env)
    t_learn = time.perf_counter()
    _cli("learn", "--run", str(run), "--seeds", str(a.seeds), "--workers", str(a.workers), *only, env=env)
    _cli("judge", "--run", str(run), "--workers", str(a.workers), *only, env=env)
    t_end = time.perf_counter()

    from anomalygen.referee import load_verdict

    by_class: dict[str, list[int]] = {}  # class -> [runs, resolved (the referee), robot's own check]
    cls_of = {t["id"]: t["hazard_class"] for t in tasks}
    for tid in built:
        for seed in range(a.seeds):
            res = run / "skills" / tid / f"seed{seed}" / "result.json"
            own = res.is_file() and json.loads(res.read_text()).get("success", False)
            verdict = load_verdict(run, tid, seed)
            row = by_class.setdefault(cls_of[tid], [0, 0, 0])
            row[0] += 1
            row[1] += int(verdict is not None and verdict.resolved)
            row[2] += int(bool(own))
    n = sum(r[0] for r in by_class.values())
    s = sum(r[1] for r in by_class.values())
    own_all = sum(r[2] for r in by_class.values())
    print("| hazard class | runs | resolved (referee) | rate | robot's own check |\n|---|---|---|---|---|")
    for hc, (k, ok, mine) in sorted(by_class.items()):
        print(f"| {hc} | {k} | {ok} | {ok / k:.0%} | {mine} |")
    print(f"| all | {n} | {s} | {s / max(n, 1):.0%} | {own_all} |")
    print(json.dumps({
        "name": "primitives",
        "tasks_in_classes": len(chosen), "tasks_built": len(built), "seeds": a.seeds,
        "runs": n, "resolved": s, "rate": round(s / max(n, 1), 3), "robot_own_check": own_all,
        "by_class": {hc: {"n": k, "resolved": ok, "robot_own_check": mine}
                     for hc, (k, ok, mine) in sorted(by_class.items())},
        "build_s": round(t_learn - t_build, 1), "learn_s": round(t_end - t_learn, 1),
        "retries": env.get("ANOMALYGEN_LEARN__RETRIES", "config"), "total_s": round(t_end - t0, 1), "run": str(run),
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main())
