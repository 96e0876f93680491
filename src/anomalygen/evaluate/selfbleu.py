"""Self-BLEU: BLEU-4 of each text against all the others, averaged (lower = more diverse).

Definition (what the paper's diversity table uses): for every text ``i``, compute NLTK's
``sentence_bleu(references=[all texts j != i], hypothesis=text i, weights=(0.25,)*4,
smoothing_function=SmoothingFunction().method1)`` and average over ``i``.

Calling ``sentence_bleu`` that way costs O(n^2) Counter constructions. Here the same numbers come
from shared counts: every text's n-gram Counter is built once, and for every n-gram we keep the
largest and second-largest count over all texts (with the owner of the largest). The clipped count
against "all references except me" is then the largest count if another text holds it, else the
second largest. The brevity penalty needs the reference length closest to the hypothesis length
(ties go to the shorter one, as in NLTK), found from a histogram of text lengths minus the text
itself. The arithmetic afterwards repeats NLTK's float operations in the same order, so the result
is identical to the reference implementation, not merely close.

Tokenisation (both paths): lower-case, then ``re.findall(r"\\w+|[^\\w\\s]")`` — words and single
punctuation marks.
"""

from __future__ import annotations

import math
import re
from collections import Counter
from collections.abc import Sequence

MAX_N = 4
WEIGHTS = (0.25, 0.25, 0.25, 0.25)
EPSILON = 0.1  # NLTK SmoothingFunction's default epsilon for method1

_TOKEN = re.compile(r"\w+|[^\w\s]")


def tokenize(text: str) -> list[str]:
    """Lower-cased words and punctuation marks; the one tokenisation every BLEU path here uses."""
    return _TOKEN.findall(text.lower())


def _ngram_counts(tokens: Sequence[str], n: int) -> Counter:
    if len(tokens) < n:
        return Counter()
    return Counter(tuple(tokens[k : k + n]) for k in range(len(tokens) - n + 1))


def self_bleu(texts: Sequence[str]) -> float:
    """Mean BLEU-4 (NLTK smoothing method 1) of each text against all others; 0.0 for < 2 texts."""
    scores = self_bleu_scores(texts)
    return math.fsum(scores) / len(scores) if scores else 0.0


def self_bleu_scores(texts: Sequence[str]) -> list[float]:
    """Per-text BLEU against the rest, equal to NLTK's ``sentence_bleu`` for each text."""
    toks = [tokenize(t) for t in texts]
    n_texts = len(toks)
    if n_texts < 2:
        return []
    counts = [[_ngram_counts(t, n) for n in range(1, MAX_N + 1)] for t in toks]

    # For every n-gram: (largest count, index of a text holding it, second-largest count).
    top: list[dict[tuple, list[int]]] = [{} for _ in range(MAX_N)]
    for idx, per_n in enumerate(counts):
        for n_minus_1, counter in enumerate(per_n):
            table = top[n_minus_1]
            for gram, c in counter.items():
                entry = table.get(gram)
                if entry is None:
                    table[gram] = [c, idx, 0]
                elif c > entry[0]:
                    entry[2] = entry[0]
                    entry[0], entry[1] = c, idx
                elif c > entry[2]:
                    entry[2] = c

    lengths = [len(t) for t in toks]
    histogram = Counter(lengths)
    distinct = sorted(histogram)

    scores = []
    for idx in range(n_texts):
        numerators, denominators = [], []
        for n_minus_1, counter in enumerate(counts[idx]):
            table = top[n_minus_1]
            clipped = 0
            for gram, c in counter.items():
                best, owner, second = table[gram]
                ref_max = second if owner == idx else best
                clipped += min(c, ref_max)
            numerators.append(clipped)
            denominators.append(max(1, sum(counter.values())))
        hyp_len = lengths[idx]
        ref_len = _closest_other_length(distinct, histogram, hyp_len, own=hyp_len)
        scores.append(_bleu_from_counts(numerators, denominators, hyp_len, ref_len))
    return scores


def _closest_other_length(distinct: list[int], histogram: Counter, hyp_len: int, *, own: int) -> int:
    """NLTK's closest_ref_length over all texts but one copy of ``own``: nearest, ties to shorter."""
    best = None
    for length in distinct:
        available = histogram[length] - (1 if length == own else 0)
        if available <= 0:
            continue
        key = (abs(length - hyp_len), length)
        if best is None or key < best:
            best = key
    assert best is not None  # at least one other text exists
    return best[1]


def _bleu_from_counts(numerators: list[int], denominators: list[int], hyp_len: int, ref_len: int) -> float:
    """NLTK corpus_bleu's final arithmetic for one sentence, in the same float operations."""
    if numerators[0] == 0:
        return 0.0
    if hyp_len > ref_len:
        bp = 1.0
    elif hyp_len == 0:
        bp = 0.0
    else:
        bp = math.exp(1 - ref_len / hyp_len)
    p_n = [(num + EPSILON) / den if num == 0 else num / den for num, den in zip(numerators, denominators, strict=False)]
    s = (w * math.log(p) for w, p in zip(WEIGHTS, p_n, strict=False) if p > 0)
    return bp * math.exp(math.fsum(s))


def self_bleu_reference(texts: Sequence[str]) -> float:
    """The slow reference: NLTK's ``sentence_bleu`` once per text against all the others."""
    scores = self_bleu_reference_scores(texts)
    return math.fsum(scores) / len(scores) if scores else 0.0


def self_bleu_reference_scores(texts: Sequence[str], indices: Sequence[int] | None = None) -> list[float]:
    """NLTK per-text scores, optionally only for ``indices`` (to time a subsample)."""
    from nltk.translate.bleu_score import SmoothingFunction, sentence_bleu

    toks = [tokenize(t) for t in texts]
    if len(toks) < 2:
        return []
    smooth = SmoothingFunction().method1
    chosen = range(len(toks)) if indices is None else indices
    return [
        float(sentence_bleu(toks[:i] + toks[i + 1 :], toks[i], weights=WEIGHTS, smoothing_function=smooth))
        for i in chosen
    ]
