"""Self-BLEU: the shared-count implementation must reproduce NLTK's sentence_bleu exactly."""

import math

import pytest

from anomalygen.evaluate.baselines import BASELINES, baseline_texts
from anomalygen.evaluate.selfbleu import (
    self_bleu,
    self_bleu_reference,
    self_bleu_reference_scores,
    self_bleu_scores,
    tokenize,
)


@pytest.mark.parametrize("stem", sorted(BASELINES))
def test_equals_nltk_on_every_baseline(stem):
    texts = baseline_texts(stem)
    fast, ref = self_bleu_scores(texts), self_bleu_reference_scores(texts)
    assert len(fast) == len(ref) == len(texts)
    assert max(abs(a - b) for a, b in zip(fast, ref, strict=False)) <= 1e-9
    assert abs(self_bleu(texts) - self_bleu_reference(texts)) <= 1e-9


def test_edge_cases_match_nltk():
    # duplicates (max count held by a copy), very short texts (< 4 tokens), an empty text,
    # repeated n-grams inside one text (clipping), and equal-distance reference lengths.
    texts = [
        "the knife is on the edge",
        "the knife is on the edge",
        "pill",
        "",
        "open open open the door the door",
        "the door is open and the the the knife",
        "a b c d e f",
        "a b c d e f g h",
    ]
    fast, ref = self_bleu_scores(texts), self_bleu_reference_scores(texts)
    assert max(abs(a - b) for a, b in zip(fast, ref, strict=False)) <= 1e-9
    assert fast[0] == pytest.approx(1.0)  # an exact copy exists among the references
    assert fast[3] == 0.0  # nothing to match


def test_identical_texts_score_one_and_disjoint_score_low():
    assert self_bleu(["a cat sat on the mat"] * 3) == pytest.approx(1.0)
    disjoint = ["alpha beta gamma delta", "epsilon zeta eta theta", "iota kappa lambda mu"]
    assert self_bleu(disjoint) == 0.0  # no unigram overlap: NLTK returns 0


def test_fewer_than_two_texts():
    assert self_bleu([]) == 0.0 and self_bleu(["only one"]) == 0.0


def test_tokenize_lowercases_and_splits_punctuation():
    assert tokenize("Open the Fridge, now!") == ["open", "the", "fridge", ",", "now", "!"]


def test_random_texts_match_nltk():
    import numpy as np

    rng = np.random.default_rng(7)
    vocab = [f"w{i}" for i in range(12)]
    texts = [" ".join(rng.choice(vocab, size=int(rng.integers(1, 12)))) for _ in range(40)]
    fast, ref = self_bleu_scores(texts), self_bleu_reference_scores(texts)
    assert max(abs(a - b) for a, b in zip(fast, ref, strict=False)) <= 1e-9
    assert not math.isnan(self_bleu(texts))
