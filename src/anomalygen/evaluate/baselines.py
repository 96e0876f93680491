"""The six public benchmark task lists shipped with the package, and the paper's published figures.

The JSONL files in ``anomalygen/data/baselines`` (sources and commits in its README.md) are the closest
public reconstruction of the texts the paper compared against; the paper's own numbers are kept next
to them so every diversity table shows ours, the recomputed baselines and the published figures.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from importlib import resources

from anomalygen.evaluate.text_metrics import task_text

BASELINES = {  # file stem -> display name, in the paper's table order
    "robogen": "RoboGen",
    "behavior100": "Behavior-100",
    "rlbench": "RLBench",
    "metaworld": "MetaWorld",
    "maniskill2": "ManiSkill2",
    "gensim": "GenSim",
}


@dataclass(frozen=True)
class PaperRow:
    """One row of the paper's diversity table (lower is more diverse)."""

    tasks: int
    self_bleu: float
    sbert: float
    vit: float
    clip: float


PAPER_DIVERSITY: dict[str, PaperRow] = {
    "AnomalyGen": PaperRow(111, 0.227, 0.245, 0.315, 0.805),
    "RoboGen": PaperRow(106, 0.287, 0.394, 0.353, 0.824),
    "Behavior-100": PaperRow(100, 0.299, 0.210, 0.389, 0.833),
    "RLBench": PaperRow(106, 0.317, 0.200, 0.375, 0.864),
    "MetaWorld": PaperRow(50, 0.322, 0.263, 0.517, 0.867),
    "ManiSkill2": PaperRow(20, 0.674, 0.194, 0.332, 0.828),
    "GenSim": PaperRow(70, 0.378, 0.288, 0.717, 0.932),
}

# Brainstorming ablation (300 proposals): Self-BLEU / SBERT / WMD as published. The paper reads all
# three as "lower is better", WMD included, although our WMD is a distance (higher = more diverse):
# the report prints the two WMD columns separately, each with its own direction.
PAPER_ABLATION = {
    "plain": (0.217, 0.553, 0.618),
    "roleplay": (0.225, 0.551, 0.605),
    "brainstorm": (0.043, 0.393, 0.511),
}

# Detection hit rate with k proposed solutions, judged by people (the paper's stage 3).
PAPER_DETECTION: dict[int, float] = {1: 0.759, 2: 0.804, 3: 0.821}



def baseline_records(stem: str) -> list[dict]:
    """The raw ``{"name", "description", "source"}`` records of one benchmark."""
    if stem not in BASELINES:
        raise KeyError(f"unknown baseline {stem!r}; choose from {sorted(BASELINES)}")
    text = resources.files("anomalygen").joinpath(f"data/baselines/{stem}.jsonl").read_text(encoding="utf-8")
    return [json.loads(line) for line in text.splitlines() if line.strip()]


def baseline_texts(stem: str) -> list[str]:
    """One metric text per task (``task_text``: name + description)."""
    return [task_text(r["name"], r["description"]) for r in baseline_records(stem)]
