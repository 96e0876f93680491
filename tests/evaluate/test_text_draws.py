"""Issue 39: every set's Self-BLEU and SBERT through one function, over seeded draws of equal size.

Tiny hand-made sets; SBERT is the shared encoder, loaded once per test process.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from anomalygen.embedding import embed, mean_pairwise_similarity
from anomalygen.evaluate.selfbleu import self_bleu
from anomalygen.evaluate.text_draws import Spread, drawn_text_metrics

EIGHT = [
    "A knife lies on the kitchen counter next to the bread.",
    "The fridge door was left open after lunch.",
    "A toddler can reach the bleach under the sink.",
    "Pills are scattered on the bedroom floor.",
    "An extension cord runs across the hallway.",
    "The window in the nursery is wide open.",
    "A pan handle sticks out over the edge of the stove.",
    "Rotten fruit sits in the bowl on the dining table.",
]


def test_identical_texts_give_one_for_both_metrics():
    m = drawn_text_metrics(["a cat sat on the mat"] * 6, rng=np.random.default_rng(0), k=3, draws=4)
    assert m.self_bleu.mean == pytest.approx(1.0) and m.self_bleu.std == pytest.approx(0.0, abs=1e-12)
    assert m.sbert.mean == pytest.approx(1.0, abs=1e-5)
    assert (m.texts, m.k, m.draws, m.small_set) == (6, 3, 4, False)


def test_draws_are_reproducible_under_a_seed_and_are_the_generators_draws():
    a = drawn_text_metrics(EIGHT, rng=np.random.default_rng(7), k=4, draws=5)
    assert a == drawn_text_metrics(EIGHT, rng=np.random.default_rng(7), k=4, draws=5)
    assert a != drawn_text_metrics(EIGHT, rng=np.random.default_rng(8), k=4, draws=5)
    # the same numbers by hand: five draws of four indices without replacement from the same generator
    rng = np.random.default_rng(7)
    draws = [np.sort(rng.choice(8, size=4, replace=False)) for _ in range(5)]
    assert all(len(set(d)) == 4 for d in draws)
    vecs = embed(EIGHT)
    bleu = [self_bleu([EIGHT[i] for i in d]) for d in draws]
    sbert = [mean_pairwise_similarity(vecs[d]) for d in draws]
    assert a.self_bleu.mean == pytest.approx(math.fsum(bleu) / 5, abs=1e-12)
    assert a.self_bleu.std == pytest.approx(float(np.std(bleu, ddof=1)), abs=1e-12)
    assert a.sbert.mean == pytest.approx(float(np.mean(sbert)), abs=1e-6)
    assert a.self_bleu.low <= a.self_bleu.mean <= a.self_bleu.high and a.sbert.std > 0


def test_a_set_smaller_than_k_is_measured_whole_and_flagged():
    three = EIGHT[:3]
    m = drawn_text_metrics(three, rng=np.random.default_rng(0), k=50, draws=100)
    assert (m.texts, m.k, m.draws, m.small_set) == (3, 3, 1, True)
    assert m.self_bleu.mean == self_bleu(three) and m.self_bleu.std == 0.0
    assert m.sbert.mean == pytest.approx(mean_pairwise_similarity(embed(three)), abs=1e-6)
    # exactly k texts: every draw is the whole set, measured once, not flagged
    exact = drawn_text_metrics(EIGHT, rng=np.random.default_rng(0), k=8, draws=100)
    assert (exact.draws, exact.small_set) == (1, False)


def test_too_few_texts_or_bad_draws_are_refused():
    with pytest.raises(ValueError, match="at least two texts"):
        drawn_text_metrics(["alone"], rng=np.random.default_rng(0))
    with pytest.raises(ValueError, match="k >= 2"):
        drawn_text_metrics(EIGHT, rng=np.random.default_rng(0), k=1)


def test_spread():
    s = Spread.of([0.1, 0.2, 0.3])
    assert s.mean == pytest.approx(0.2) and s.std == pytest.approx(0.1)
    assert (s.low, s.high) == (pytest.approx(0.105), pytest.approx(0.295))
    assert Spread.of([0.4]) == Spread(0.4, 0.0, 0.4, 0.4)
