"""Self-BLEU and SBERT similarity of a set of texts, controlled for set size by repeated draws.

Self-BLEU of a set grows with its size (every text gains references), so sets of 20 and 111 texts
are not comparable as wholes. Every set here, each baseline and ours, goes through the one function
``drawn_text_metrics``: ``draws`` times, ``k`` texts drawn without replacement by an explicit
``numpy.random.Generator``; Self-BLEU (``evaluate/selfbleu.py``, equal to NLTK) and mean pairwise
SBERT cosine (``anomalygen.embedding``) of each draw; the mean and spread over the draws. A set of
fewer than ``k`` texts is measured whole and flagged (``small_set``); a set of exactly ``k`` texts is
measured whole too (every draw would be the same set). Both metrics are taken on the same draws.

The text of every set is one field, ``TEXT_FIELD``: the full description of each task as the public
task lists give it (the baselines' ``description``, our ``TaskProposal.description``). Behavior-100
publishes no descriptions; its field holds the activity name (``data/baselines/README.md``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from anomalygen.config import EvaluateConfig
from anomalygen.evaluate.selfbleu import self_bleu

TEXT_FIELD = "description"  # the one field every set is measured on
DRAW_SIZE: int = EvaluateConfig.model_fields["draw_size"].default  # texts per draw (k); why: config.py
DRAWS: int = EvaluateConfig.model_fields["draws"].default  # draws per set (R)


@dataclass(frozen=True)
class Spread:
    """A metric over the draws: mean, sample standard deviation, and the 2.5-97.5 % percentile range."""

    mean: float
    std: float
    low: float
    high: float

    @classmethod
    def of(cls, values: Sequence[float]) -> Spread:
        arr = np.asarray(values, dtype=np.float64)
        std = float(arr.std(ddof=1)) if len(arr) > 1 else 0.0
        low, high = (float(v) for v in np.percentile(arr, [2.5, 97.5]))
        return cls(mean=math.fsum(arr.tolist()) / len(arr), std=std, low=low, high=high)


@dataclass(frozen=True)
class DrawnTextMetrics:
    """Self-BLEU and SBERT similarity of one set over its draws (lower = more diverse)."""

    texts: int  # texts in the set
    k: int  # texts per draw (the whole set when it has no more than the requested draw size)
    draws: int  # draws measured (1 when every draw would be the whole set)
    small_set: bool  # fewer texts than the requested draw size: measured whole, not comparable in size
    self_bleu: Spread
    sbert: Spread


def set_texts(items: Iterable) -> list[str]:
    """``TEXT_FIELD`` of each item (a mapping such as a baseline record, or a ``TaskProposal``), stripped."""
    return [str(item[TEXT_FIELD] if isinstance(item, dict) else getattr(item, TEXT_FIELD)).strip() for item in items]


def drawn_text_metrics(texts: Sequence[str], *, rng: np.random.Generator, k: int = DRAW_SIZE,
                       draws: int = DRAWS) -> DrawnTextMetrics:
    """Self-BLEU and SBERT mean pairwise similarity over ``draws`` draws of ``k`` texts without replacement.

    A set of ``k`` texts or fewer is measured once, whole (``small_set`` when fewer than ``k``).
    """
    from anomalygen.embedding import embed, mean_pairwise_similarity

    n = len(texts)
    if n < 2:
        raise ValueError(f"Self-BLEU and SBERT similarity need at least two texts, got {n}")
    if k < 2 or draws < 1:
        raise ValueError(f"need k >= 2 texts per draw and at least one draw, got k={k}, draws={draws}")
    whole = n <= k
    samples = [np.arange(n)] if whole else [np.sort(rng.choice(n, size=k, replace=False)) for _ in range(draws)]
    vecs = embed(list(texts))  # once per set; a draw is a sub-matrix
    bleu = [self_bleu([texts[i] for i in idx]) for idx in samples]
    sbert = [mean_pairwise_similarity(vecs[idx]) for idx in samples]
    return DrawnTextMetrics(texts=n, k=min(k, n), draws=len(samples), small_set=n < k,
                            self_bleu=Spread.of(bleu), sbert=Spread.of(sbert))
