"""The proactive loop against the hidden truth, on every class: the issue's 111-task table.

Runs the real pipeline through the CLI: ``brainstorm --engine knowledge --n N --seed S``, ``build``
(default judgement mix: near-misses, second hazards, hazard-free scenes), ``detect --detector rules``,
then plan, learn and judge twice from the same scenes and detections: from perception (the default,
``plan.source = detected``) and with the oracle (``ground_truth``: the builder's class and bindings).
Every figure is the referee's (``anomalygen judge``: each run's final state released, settled and
judged against truth.json). Prints the detection scores and, per mode, the table by class (hazards
present, detected, planned, resolved — no class firing on the object and no new hazard in the run;
runs that created a hazard or acted on a safe object), then one JSON line.

    .venv/bin/python benchmarks/bench_loop.py [--n 111] [--seed 0] [--seeds 1] [--workers 2] [--out DIR]
        [--compare-detectors N] [--noise] [--skip-learn]

``--compare-detectors N`` also runs the LLM and hybrid detectors (the configured LLM backend; by
default the bundled tiny GGUF, which measures the mechanics, not judgement) on the first N scenes
and scores all three detectors on those same N scenes. ``--noise`` also detects with perception noise
(``detect --noise``, the ``detect.noise`` settings) on a copy of the run and scores that too; plans and
skills stay on the noise-free detections.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from anomalygen import procs


def _cli(*args: str, env=None) -> None:
    exe = Path(sys.executable).with_name("anomalygen")
    subprocess.run([str(exe), *args, "--quiet"], check=True, env=env, preexec_fn=procs.end_with_parent)


def _copy_run(src: Path, dst: Path) -> None:
    """The run up to detection, hard-linked (scenes are large; nothing later rewrites them)."""
    def link(a, b):
        try:
            os.link(a, b)
        except OSError:
            shutil.copy2(a, b)

    shutil.copytree(src, dst, copy_function=link, ignore=shutil.ignore_patterns("plans", "skills", "report"))


def _detection_scores(folder: Path, ids: set[str] | None = None):
    """The run's detections scored against truth.json (only the tasks in ``ids`` when given)."""
    from anomalygen.evaluate.run_metrics import load_detections, load_manifests
    from anomalygen.referee.score import score_detections
    from anomalygen.runfolder import RunFolder

    run = RunFolder(folder)
    tasks = [t for t in run.load_tasks() if ids is None or t.id in ids]
    dets = [d for d in load_detections(run) if ids is None or d.task_id in ids]
    return score_detections(dets, load_manifests(run, tasks), 3)


def _summary(sc) -> dict:
    return {"recall": sc.recall, "precision": sc.precision, "f1": sc.f1, "false_alarm_rate": sc.false_alarm_rate,
            "hit_at_1_single": sc.hit_at_k.get(1), "hazards": sc.hazards, "scenes": sc.scenes,
            "hazard_free": sc.hazard_free_scenes}


def main() -> int:
    from anomalygen.evaluate.hazard_table import hazard_table, markdown
    from anomalygen.runfolder import RunFolder

    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=111)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--seeds", type=int, default=1, help="executions per scene")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--out", default=None, help="folder for the runs (default: a temporary one)")
    ap.add_argument("--compare-detectors", type=int, default=0, metavar="N",
                    help="score rules, llm and hybrid detection on the first N scenes")
    ap.add_argument("--noise", action="store_true", help="also score rule detection with perception noise")
    ap.add_argument("--skip-learn", action="store_true", help="stop after detection")
    a = ap.parse_args()
    root = Path(a.out or tempfile.mkdtemp(prefix="bench_loop_"))
    base = root / "detected"
    env = {**os.environ, "ANOMALYGEN_LEARN__VIDEO": "false"}
    t0 = time.perf_counter()
    _cli("brainstorm", "--run", str(base), "--engine", "knowledge", "--n", str(a.n), "--seed", str(a.seed), env=env)
    _cli("build", "--run", str(base), "--workers", str(a.workers), "--seed", str(a.seed), env=env)
    _cli("detect", "--run", str(base), "--detector", "rules", env=env)
    t_detect = time.perf_counter()
    _copy_run(base, root / "oracle")
    out: dict = {"name": "loop", "n": a.n, "seed": a.seed, "seeds": a.seeds}
    ids = [t.id for t in RunFolder(base).load_tasks()]
    scores = _detection_scores(base)
    print(f"detection (rules) against truth.json: {scores.model_dump_json()}")
    out["detection"] = _summary(scores)
    if a.noise:
        noisy = root / "detect_noise"
        _copy_run(base, noisy)
        _cli("detect", "--run", str(noisy), "--detector", "rules", "--noise", "--force", env=env)
        out["detection_noise"] = _summary(_detection_scores(noisy))
        print(f"detection (rules, perception noise) against truth.json: {json.dumps(out['detection_noise'])}")
    if a.compare_detectors:
        out["detectors"] = _compare_detectors(root, base, ids, a.compare_detectors, env)
    for mode, folder in (() if a.skip_learn else (("detected", base), ("ground_truth", root / "oracle"))):
        t = time.perf_counter()
        menv = {**env, "ANOMALYGEN_PLAN__SOURCE": mode}
        _cli("plan", "--run", str(folder), env=menv)
        _cli("learn", "--run", str(folder), "--seeds", str(a.seeds), "--workers", str(a.workers), env=menv)
        _cli("judge", "--run", str(folder), "--workers", str(a.workers), env=menv)  # the referee, after the robot
        table = hazard_table(RunFolder(folder), ids, a.seeds)
        print(markdown(table, f"plan.source = {mode}"))
        tot = table.total
        out[mode] = {"hazards": tot.hazards, "detected": tot.detected, "planned": tot.planned, "runs": tot.runs,
                     "resolved": tot.resolved, "resolved_rate": round(tot.resolved / tot.runs, 3) if tot.runs else None,
                     "runs_with_new_hazards": table.runs_with_new_hazards, "runs_acting_on_safe": table.runs_acting_on_safe,
                     "plan_learn_s": round(time.perf_counter() - t, 1),
                     "by_class": {k: v.model_dump() for k, v in table.by_class.items()}}
    out["build_detect_s"] = round(t_detect - t0, 1)
    out["wall_s"] = round(time.perf_counter() - t0, 1)
    print(json.dumps(out))
    return 0


def _compare_detectors(root: Path, base: Path, ids: list[str], n: int, env: dict) -> dict:
    """Rules, LLM and hybrid detection scored against truth.json on the same first ``n`` built scenes."""
    built = [t for t in ids if (base / "scenes" / t / "scene.xml").exists()][:n]
    only = [x for t in built for x in ("--only", t)]
    res = {}
    env = {"ANOMALYGEN_LLM__BACKEND": "llamacpp", **env}  # the bundled GGUF unless a backend is configured
    for det in ("rules", "llm", "hybrid"):
        folder = root / f"detector_{det}"
        _copy_run(base, folder)
        (folder / "detections.jsonl").unlink(missing_ok=True)
        t = time.perf_counter()
        _cli("detect", "--run", str(folder), "--detector", det, "--force", *only, env=env)
        res[det] = {**_summary(_detection_scores(folder, set(built))), "wall_s": round(time.perf_counter() - t, 1)}
        print(f"detector {det} on {len(built)} scenes: {json.dumps(res[det])}")
    return res


if __name__ == "__main__":
    raise SystemExit(main())
