"""Any agent, judged: the baselines on a frozen suite, and the Pipeline agent against the loop, run by run.

Builds the suite (``anomalygen suite build``, unless ``--suite-dir`` names a built one), runs
``anomalygen bench`` for each agent, and — unless ``--loop DIR`` names a run of ``bench_loop.py``'s
perception mode on the same scenes — runs that mode itself on a hard-linked copy of the suite (detect
with the rules, plan from perception, learn, judge: ``bench_loop.py``'s commands). Then it compares the
Pipeline agent's runs with the loop's, run by run: the referee's status, the hazards resolved, and
whether the final simulator states are identical. Prints each agent's table line, every run that
differs, and one JSON line.

    .venv/bin/python benchmarks/bench_agents.py [--suite anomaly-111] [--suite-dir DIR] [--loop DIR]
        [--agents Pipeline,DoNothing,Random] [--workers 2] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from bench_loop import _cli, _copy_run  # noqa: E402  (the loop's own commands, not a copy of them)


def compare(bench: Path, loop: Path, ids: list[str]) -> dict:
    """The Pipeline agent's runs against the loop's, run by run (seed 0)."""
    import numpy as np

    from anomalygen.referee import load_verdict
    from anomalygen.runfolder import RunFolder
    from anomalygen.scene_files import FINAL_STATE

    b, lp = RunFolder(bench), RunFolder(loop)
    same_status = same_state = 0
    differ = []
    for tid in ids:
        vb, vl = load_verdict(b, tid, 0), load_verdict(lp, tid, 0)
        fb, fl = b.skill_dir(tid, 0) / FINAL_STATE, lp.skill_dir(tid, 0) / FINAL_STATE
        identical = fb.is_file() and fl.is_file() and np.array_equal(np.load(fb)["state"], np.load(fl)["state"])
        same_state += int(identical)
        agree = vb is not None and vl is not None and vb.status == vl.status and \
            [(h.object, h.resolved) for h in vb.hazards] == [(h.object, h.resolved) for h in vl.hazards]
        same_status += int(agree)
        if not agree or not identical:
            differ.append({"task": tid, "bench": vb.status if vb else None, "loop": vl.status if vl else "no run",
                           "same_final_state": identical,
                           "bench_resolved": [h.object for h in vb.hazards if h.resolved] if vb else [],
                           "loop_resolved": [h.object for h in vl.hazards if h.resolved] if vl else []})
    return {"runs": len(ids), "agree": same_status, "agree_rate": round(same_status / len(ids), 4) if ids else None,
            "identical_final_states": same_state, "differ": differ}


def main() -> int:
    from anomalygen.bench.suites import open_suite

    ap = argparse.ArgumentParser()
    ap.add_argument("--suite", default="anomaly-111")
    ap.add_argument("--suite-dir", type=Path, default=None, help="a built suite (default: build --suite into --out)")
    ap.add_argument("--loop", type=Path, default=None, help="bench_loop.py's <out>/detected of the same scenes")
    ap.add_argument("--agents", default="Pipeline,DoNothing,Random")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args()
    root = a.out or Path(tempfile.mkdtemp(prefix="bench_agents_"))
    env = {**os.environ, "ANOMALYGEN_LEARN__VIDEO": "false"}
    t0 = time.perf_counter()
    suite_dir = a.suite_dir or root / "suite"
    if a.suite_dir is None:
        _cli("suite", "build", a.suite, "--out", str(suite_dir), "--workers", str(a.workers), env=env)
    suite = open_suite(suite_dir)
    out: dict = {"name": "agents", "suite": suite.label, "scenes": len(suite.task_ids), "agents": {}}
    for name in a.agents.split(","):
        t = time.perf_counter()
        folder = root / name.lower()
        _cli("bench", "--agent", f"anomalygen.agents:{name}", "--suite", str(suite_dir), "--out", str(folder),
             "--workers", str(a.workers), env=env)
        report = json.loads((folder / "bench.json").read_text())
        out["agents"][name] = {k: report[k] for k in ("runs", "runs_with_hazards", "resolved", "hazard_free_runs",
                                                      "left_alone", "runs_with_new_hazards", "runs_acting_on_safe",
                                                      "failed")}
        out["agents"][name]["hazards_resolved"] = sum(r["resolved"] for r in report["by_class"].values())
        out["agents"][name]["wall_s"] = round(time.perf_counter() - t, 1)
        print(f"{name}: {json.dumps(out['agents'][name])}")
    if "Pipeline" in a.agents.split(","):
        loop = a.loop
        if loop is None:  # bench_loop.py's perception mode on the same scenes
            loop = root / "loop"
            if not loop.exists():
                _copy_run(suite_dir, loop)
            for stage in ("detect", "plan", "learn", "judge"):
                extra = ["--detector", "rules"] if stage == "detect" else ["--workers", str(a.workers)] \
                    if stage in ("learn", "judge") else []
                _cli(stage, "--run", str(loop), *extra, env={**env, "ANOMALYGEN_PLAN__SOURCE": "detected"})
        out["pipeline_vs_loop"] = compare(root / "pipeline", loop, suite.task_ids)
        cmp = out["pipeline_vs_loop"]
        print(f"Pipeline vs the loop: {cmp['agree']} of {cmp['runs']} runs agree, "
              f"{cmp['identical_final_states']} identical final states")
        for d in cmp["differ"]:
            print(f"  {json.dumps(d)}")
    out["wall_s"] = round(time.perf_counter() - t0, 1)
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
