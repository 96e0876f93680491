"""Brainstorming figures: offline engine speed at n=111, and the plain/roleplay/brainstorm ablation.

Run: ``.venv/bin/python benchmarks/bench_brainstorm.py [--runs 30] [--json]``. Prints one JSON object:
- ``engine_111``: wall seconds for 111 proposals (SBERT already loaded, and the load time itself),
  near-duplicates rejected by the novelty filter, classes and categories covered.
- ``ablation``: per mode, pooled proposals, mean pairwise SBERT similarity, Self-BLEU, distinct scenarios.
"""

from __future__ import annotations

import argparse
import json
import time


def bench_engine(n: int = 111) -> dict:
    from anomalygen.brainstorm.knowledge_engine import KnowledgeEngine
    from anomalygen.embedding import embed
    from anomalygen.knowledge import load_kb

    t0 = time.perf_counter()
    embed(["load"])
    load_s = time.perf_counter() - t0
    t1 = time.perf_counter()
    engine = KnowledgeEngine(seed=0)
    tasks = engine.run(n)
    wall = time.perf_counter() - t1
    kb = load_kb()
    return {
        "n": len(tasks),
        "sbert_load_s": round(load_s, 2),
        "wall_s": round(wall, 2),
        "proposals_per_s": round(len(tasks) / wall, 1),
        "near_duplicates_rejected": engine.rejected_near_duplicates,
        "same_scenario_rejected": engine.rejected_same_scenario,
        "classes": len({t.hazard_class for t in tasks}),
        "paper_classes": len({t.hazard_class for t in tasks if kb.hazard_classes[t.hazard_class].paper_class}),
        "categories": len({t.category for t in tasks}),
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=30)
    ap.add_argument("--json", action="store_true", help="(output is always JSON; kept for symmetry)")
    args = ap.parse_args()
    from anomalygen.brainstorm.ablation import run_ablation

    out = {"engine_111": bench_engine(), "ablation": run_ablation(runs=args.runs).as_dict()}
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
