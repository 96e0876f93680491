"""Switch-off tasks end to end through ``plan`` and ``learn``: the shipped SAC warm start vs the primitive.

On a run folder whose switch-off scenes are built (e.g. the held-out folder of
``benchmarks/train_warm_start.py``), plans every ``switch_off_appliance`` task with the knowledge
planner (which hands each knob or switch that is on to SAC) and runs the learn stage with ``--seeds``
seeds, videos off. ``--method primitive`` rewrites the plans' sub-tasks to the primitive first, for
the baseline on the same scenes. Prints a table and one JSON line: runs the referee judged resolved
over (task, seed) runs (the headline), the robot's own check beside it, sub-task success, how many
SAC sub-tasks were fine-tuned or fell back to the primitive, wall time.

    .venv/bin/python benchmarks/bench_sac_switch_off.py [--run /tmp/ws/test] [--seeds 2] [--sac-steps 1000]
        [--method sac|primitive]

Without ``--run`` (as ``make bench`` calls it) the held-out folder is made first in a temporary
directory: 300 knowledge tasks brainstormed with seed 1, the switch-off ones built (about 2 min).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from anomalygen import procs

CLASS = "switch_off_appliance"


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--run", default=None)
    ap.add_argument("--seeds", type=int, default=1)
    ap.add_argument("--sac-steps", type=int, default=1000)
    ap.add_argument("--method", choices=("sac", "primitive"), default="sac")
    a = ap.parse_args()
    if a.run is None:
        import tempfile

        from train_warm_start import make_run  # the sibling script: the same held-out set-up

        run = Path(tempfile.mkdtemp(prefix="bench_sac_switch_off_")) / "run"
        make_run(run, 1)
    else:
        run = Path(a.run)
    exe = Path(sys.executable).with_name("anomalygen")
    env = {**os.environ, "ANOMALYGEN_LEARN__VIDEO": "false", "ANOMALYGEN_PLAN__SOURCE": "ground_truth"}
    tasks = [json.loads(x) for x in (run / "tasks.jsonl").read_text().splitlines() if x.strip()]
    ids = [t["id"] for t in tasks if t["hazard_class"] == CLASS and (run / "scenes" / t["id"] / "scene.json").is_file()]
    only = [x for tid in ids for x in ("--only", tid)]
    subprocess.run([str(exe), "plan", "--run", str(run), "--force", *only, "--quiet"], check=True, env=env, preexec_fn=procs.end_with_parent)
    if a.method == "primitive":
        for tid in ids:
            p = run / "plans" / f"{tid}.json"
            plan = json.loads(p.read_text())
            for st in plan["subtasks"]:
                st["method"] = "primitive"
            p.write_text(json.dumps(plan))
    t0 = time.perf_counter()
    subprocess.run([str(exe), "learn", "--run", str(run), "--seeds", str(a.seeds), "--sac-steps", str(a.sac_steps),
                    "--workers", "1", "--force", *only, "--quiet"], check=True, env=env, preexec_fn=procs.end_with_parent)
    wall = time.perf_counter() - t0
    from anomalygen.evaluate.verdicts import verdict_of
    from anomalygen.runfolder import RunFolder

    folder = RunFolder(run)
    runs = ok = resolved = judged = sub = sub_ok = tuned = fell = 0
    print("| task | seed | referee | robot's own check | sub-tasks | detail |\n|---|---|---|---|---|---|")
    for tid in ids:
        for seed in range(a.seeds):
            f = run / "skills" / tid / f"seed{seed}" / "result.json"
            if not f.is_file():
                continue
            r = json.loads(f.read_text())
            verdict = verdict_of(folder, tid, seed)
            runs += 1
            ok += bool(r["success"])
            judged += verdict is not None
            resolved += bool(verdict is not None and verdict.resolved)
            subs = r["subtasks"]
            sub += len(subs)
            sub_ok += sum(s["success"] for s in subs)
            tuned += sum("SAC steps" in s["detail"] for s in subs)
            fell += sum("fell back" in s["detail"] for s in subs)
            first = subs[0]["detail"][:110] if subs else ""
            status = verdict.status if verdict is not None else "no truth"
            print(f"| {tid[:34]} | {seed} | {status} | {r['success']} | {sum(s['success'] for s in subs)}/{len(subs)} "
                  f"| {first} |")
    print(json.dumps({"method": a.method, "runs": runs, "judged": judged, "resolved": resolved,
                      "resolved_rate": round(resolved / max(1, judged), 3),
                      "robot_own_check": ok, "robot_own_check_rate": round(ok / max(1, runs), 3),
                      "subtasks": sub, "subtask_success": sub_ok, "fine_tuned": tuned, "fell_back": fell,
                      "learn_wall_s": round(wall, 1), "sac_steps": a.sac_steps}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
