"""The six public benchmark task lists shipped with the package, and the paper's published figures.

The JSONL files in ``anomalygen/data/baselines`` (sources and commits in its README.md) are the closest
public reconstruction of the texts the paper compared against; the paper's own numbers are kept next
to them, and every diversity table shows them in a column of their own, "as published; not
reproducible from public code", beside the figures measured here.
"""

from __future__ import annotations

import json
from importlib import resources

from anomalygen.evaluate.text_draws import set_texts
from anomalygen.schema import Strict

BASELINES = {  # file stem -> display name, in the paper's table order
    "robogen": "RoboGen",
    "behavior100": "Behavior-100",
    "rlbench": "RLBench",
    "metaworld": "MetaWorld",
    "maniskill2": "ManiSkill2",
    "gensim": "GenSim",
}


class PaperRow(Strict):
    """One row of the paper's diversity table as published (lower is more diverse).

    Neither RoboGen's nor AnomalyGen's public code computes Self-BLEU or embedding similarity, and the
    paper does not say which text of a task it used, so these figures cannot be reproduced from public
    code; on the public task lists our NLTK-equal Self-BLEU gives other values, in another order.
    """

    tasks: int
    self_bleu: float
    sbert: float
    vit: float
    clip: float


def _paper(tasks: int, self_bleu: float, sbert: float, vit: float, clip: float) -> PaperRow:
    return PaperRow(tasks=tasks, self_bleu=self_bleu, sbert=sbert, vit=vit, clip=clip)


# The paper's "AnomalyGen" row is its LLM engine (GPT-4); there is no published figure for our offline
# engine, so it is no target for it.
PAPER_DIVERSITY: dict[str, PaperRow] = {
    "AnomalyGen": _paper(111, 0.227, 0.245, 0.315, 0.805),
    "RoboGen": _paper(106, 0.287, 0.394, 0.353, 0.824),
    "Behavior-100": _paper(100, 0.299, 0.210, 0.389, 0.833),
    "RLBench": _paper(106, 0.317, 0.200, 0.375, 0.864),
    "MetaWorld": _paper(50, 0.322, 0.263, 0.517, 0.867),
    "ManiSkill2": _paper(20, 0.674, 0.194, 0.332, 0.828),
    "GenSim": _paper(70, 0.378, 0.288, 0.717, 0.932),
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
    """One metric text per task: its full description (``text_draws.TEXT_FIELD``), as for every set."""
    return set_texts(baseline_records(stem))
