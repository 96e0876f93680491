"""Brainstorming ablation with the offline knowledge engine: plain vs. role-play vs. brainstorm.

Run: ``.venv/bin/python scripts/brainstorm_ablation.py [--seed 0] [--targets 10] [--runs 30] [--per-run 10] [--json]``

Default protocol: 10 random target assets; for each mode 30 runs x 10 proposals = 300 proposals,
pooled per mode. Prints mean pairwise Sentence-BERT similarity and Self-BLEU (lower = more diverse),
the number of distinct scenarios (class, hazard object, placement, room) and of hazard classes.
"""

from __future__ import annotations

import argparse
import json
import os
import sys

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("TOKENIZERS_PARALLELISM", "false")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--targets", type=int, default=10)
    ap.add_argument("--runs", type=int, default=30)
    ap.add_argument("--per-run", type=int, default=10)
    ap.add_argument("--agents", type=int, default=10)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--no-bleu", action="store_true")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args(argv)

    from anomalygen.brainstorm.ablation import format_table, run_ablation

    result = run_ablation(
        seed=args.seed,
        n_targets=args.targets,
        runs=args.runs,
        per_run=args.per_run,
        agents=args.agents,
        rounds=args.rounds,
        bleu=not args.no_bleu,
    )
    print(json.dumps(result.as_dict(), indent=2) if args.json else format_table(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
