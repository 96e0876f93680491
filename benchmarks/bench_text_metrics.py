"""Text diversity measured alike for the six public baselines and a seed-0 knowledge-engine run.

Run: ``.venv/bin/python benchmarks/bench_text_metrics.py [--tasks runs/x/tasks.jsonl] [--seed 0]
[--draw-size 50] [--draws 100]``. Without ``--tasks`` it first makes the run the table reports:
``anomalygen brainstorm --engine knowledge --n 111 --seed 0 --run <tmp> --quiet``.

Every set goes through ``evaluate.text_draws.drawn_text_metrics`` on the full description of each
task, through the same rows ``anomalygen evaluate`` writes (the run's draws keyed "run", so this table
equals that of ``anomalygen evaluate`` on the same tasks and seed). Prints the table, then one JSON
object as the last line (``benchmarks/run_all.py``).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from anomalygen import procs
from anomalygen.config import EvaluateConfig


def knowledge_run(out: Path, *, n: int = 111, seed: int = 0) -> Path:
    """The seed-0 offline-engine run's tasks.jsonl (the CLI, as a user makes it)."""
    exe = Path(sys.executable).with_name("anomalygen")
    subprocess.run([str(exe), "brainstorm", "--engine", "knowledge", "--n", str(n), "--seed", str(seed),
                    "--run", str(out), "--quiet"], check=True, preexec_fn=procs.end_with_parent)
    return out / "tasks.jsonl"


def main() -> int:
    defaults = EvaluateConfig()
    ap = argparse.ArgumentParser()
    ap.add_argument("--tasks", type=Path, help="a run's tasks.jsonl (default: make the seed-0, n=111 run)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--draw-size", type=int, default=defaults.draw_size)
    ap.add_argument("--draws", type=int, default=defaults.draws)
    args = ap.parse_args()

    from rich.console import Console

    from anomalygen.evaluate.diversity import baseline_rows, rich_table, text_row
    from anomalygen.evaluate.text_draws import set_texts
    from anomalygen.runfolder import read_jsonl
    from anomalygen.schema import TaskProposal

    with tempfile.TemporaryDirectory(prefix="bench_text_") as tmp:
        t0 = time.perf_counter()
        path = args.tasks or knowledge_run(Path(tmp) / "m111", seed=args.seed)
        brainstorm_s = time.perf_counter() - t0
        tasks = read_jsonl(path, TaskProposal)
    engines = sorted({str(t.provenance.engine) for t in tasks})
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    run = text_row(f"this run ({', '.join(engines)} engine, {len(tasks)} tasks)", "run", set_texts(tasks),
                   seed=args.seed, key="run", draw_size=args.draw_size, draws=args.draws, timings=timings)
    rows = [run, *baseline_rows(seed=args.seed, draw_size=args.draw_size, draws=args.draws, timings=timings)]
    metrics_s = time.perf_counter() - t0
    Console(width=160).print(rich_table(rows))
    out = {"name": "text_metrics_drawn", "seed": args.seed, "draw_size": args.draw_size, "draws": args.draws,
           "brainstorm_s": round(brainstorm_s, 2), "metrics_s": round(metrics_s, 2),
           "sets": {r.name: {"texts": r.tasks, "small_set": r.small_set,
                             "self_bleu": _round(r.self_bleu), "self_bleu_sd": _round(r.self_bleu_std),
                             "sbert": _round(r.sbert), "sbert_sd": _round(r.sbert_std)}
                    for r in rows if r.kind != "paper"}}
    print(json.dumps(out))
    return 0


def _round(x: float | None) -> float | None:
    return None if x is None else round(x, 4)


if __name__ == "__main__":
    sys.exit(main())
