"""Detection figures: rule-detector speed and accuracy, text-judge calibration, scores on built runs.

Run: ``.venv/bin/python benchmarks/bench_detect.py [--run runs/x] [--clutter-run runs/x5] [--json]``.
Prints one JSON object.
- ``kb_sweep``: the rule detector on every (class, object, placement) the knowledge base can set up, as
  minimal synthetic scene graphs, without and with 5 clutter objects (``anomalygen.detect.kbcheck``).
- ``rules_speed``: scene graphs per second through the rule detector (22 classes' preconditions).
- ``judge``: the text judge's SBERT threshold re-calibrated on ``data/judge/calibration.jsonl`` with
  precision, recall and leave-one-task-out figures, and judged pairs per second (the text judge is a
  diagnostic; detection is scored against the truth).
- ``run`` / ``clutter_run``: the rule detector on the scenes of built run folders (read only: nothing
  is written), scored against each scene's truth.json: recall, precision, F1, false alarms on
  hazard-free scenes, hit@1..3 on single-hazard scenes, the hazards missed; and the drop in
  "first claim names a truth hazard" between the two runs.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path


def bench_sweep() -> dict:
    from anomalygen.detect.kbcheck import sweep

    return {f"clutter{n}": sweep(n_clutter=n) for n in (0, 5)}


def bench_rules_speed(repeat: int = 3) -> dict:
    from anomalygen.detect.kbcheck import cases
    from anomalygen.detect.rules import RuleDetector
    from anomalygen.knowledge import load_kb

    kb = load_kb()
    det = RuleDetector(kb)
    graphs = [c.graph for c in cases(kb, n_clutter=5)]
    start = time.perf_counter()
    for _ in range(repeat):
        for gr in graphs:
            det.detect(gr, 3)
    wall = time.perf_counter() - start
    n = repeat * len(graphs)
    return {"graphs": n, "objects_per_graph": round(sum(len(g.objects) for g in graphs) / len(graphs), 1),
            "wall_s": round(wall, 3), "graphs_per_s": round(n / wall, 1)}


def bench_judge() -> dict:
    from anomalygen.embedding import encoder
    from anomalygen.evaluate.judge_calibration import calibrate, load_pairs, similarities

    pairs = load_pairs()
    encoder()  # load once, outside the timing
    start = time.perf_counter()
    sims = similarities(pairs)
    wall = time.perf_counter() - start
    result = calibrate(pairs, sims)
    out = result.as_dict()
    out["pairs_per_s"] = round(len(pairs) / wall, 1)
    return out


def bench_run(root: Path, k: int = 3) -> dict:
    """Rule detection on every built scene of a run, in memory, scored against its truth.json."""
    from anomalygen.config import load_settings
    from anomalygen.detect.stage import detect_scene, make_detector
    from anomalygen.evaluate import run_metrics as rm
    from anomalygen.evaluate.detection_report import summarise
    from anomalygen.evaluate.detection_scores import finds
    from anomalygen.runfolder import RunFolder, try_read_model
    from anomalygen.schema import SceneGraph

    run = RunFolder.open(root)
    settings = load_settings(None, {"quiet": True, "detect.k": k, "detect.detector": "rules"})
    detector = make_detector(settings)
    tasks = run.load_tasks()
    dets = []
    start = time.perf_counter()
    for t in tasks:
        graph = try_read_model(run.scene_dir(t.id) / "scene_graph.json", SceneGraph)
        if graph is not None:
            dets.append(detect_scene(t.id, graph, settings, detector=detector))
    wall = time.perf_counter() - start
    manifests = rm.load_manifests(run, tasks)
    report = summarise(dets, tasks, manifests, k)
    sc = report.overall
    return {
        "run": str(root),
        "tasks": len(tasks),
        "scenes": report.scenes,
        "against_truth": sc.model_dump() if sc else None,
        "misses": [m.model_dump() for m in report.misses],
        "missing_scenes": len(report.missing_scenes),
        "wall_s": round(wall, 3),
        # per scene: does the first claim name one of the scene's truth hazards (None: no truth, or no hazard)
        "first_claim_true": {d.task_id: (any(finds(d.hypotheses[:1], z) for z in manifests[d.task_id].hazards)
                                         if d.task_id in manifests and manifests[d.task_id].hazards else None)
                             for d in dets},
    }


def clutter_drop(plain: dict, cluttered: dict) -> dict:
    """How often the first claim names a truth hazard, in both runs, over the scenes with a hazard
    built in both (the same tasks, with and without clutter)."""
    a, b = plain["first_claim_true"], cluttered["first_claim_true"]
    both = sorted(t for t in set(a) & set(b) if a[t] is not None and b[t] is not None)
    if not both:
        return {"common_scenes": 0}

    def rate(r: dict) -> float:
        return sum(1 for t in both if r[t]) / len(both)

    return {"common_scenes": len(both), "first_claim_true_plain": round(rate(a), 4),
            "first_claim_true_clutter": round(rate(b), 4), "drop": round(rate(a) - rate(b), 4),
            "changed": [t for t in both if a[t] != b[t]]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", type=Path, help="a built run folder (brainstorm + build)")
    ap.add_argument("--clutter-run", type=Path, help="the same tasks built with --clutter 5")
    ap.add_argument("--skip-judge", action="store_true")
    ap.add_argument("--json", action="store_true", help="compact JSON")
    args = ap.parse_args()
    out: dict = {"kb_sweep": bench_sweep(), "rules_speed": bench_rules_speed()}
    if not args.skip_judge:
        out["judge"] = bench_judge()
    if args.run:
        out["run"] = bench_run(args.run)
    if args.clutter_run:
        out["clutter_run"] = bench_run(args.clutter_run)
        if args.run:
            out["clutter_effect"] = clutter_drop(out["run"], out["clutter_run"])
    print(json.dumps(out, indent=None if args.json else 2, default=str))


if __name__ == "__main__":
    main()
