"""Semantic text diversity: mean pairwise SBERT similarity and Word Mover's Distance.

Both take the same texts as Self-BLEU: the full description of each task (``text_draws.TEXT_FIELD``).
Lower SBERT similarity and higher WMD mean more diverse tasks. The diversity table measures SBERT and
Self-BLEU over repeated draws of equal size (``text_draws.py``); WMD is kept for the brainstorming
ablation, on the run's whole sets.

Word vectors for WMD: nothing like word2vec/GloVe can be fetched offline here, so WMD uses the
input word-piece embedding matrix of the bundled all-MiniLM-L6-v2 (the same model behind SBERT,
``anomalygen.embedding.encoder()``). Texts are split by MiniLM's own WordPiece tokenizer (special
tokens dropped), each text becomes a normalised bag of word pieces, the ground cost is the cosine
distance (1 - cos) between word-piece vectors, and ``ot.emd2`` solves the exact transport problem.
Cosine rather than Euclidean cost keeps values in [0, 2] regardless of the embedding scale; this is a
documented substitute, so our WMD figures are comparable with each other, not with the paper's.
"""

from __future__ import annotations

import itertools
from collections import Counter
from collections.abc import Sequence

import numpy as np


def sbert_similarity(texts: Sequence[str]) -> float:
    """Mean pairwise cosine similarity of Sentence-BERT embeddings (0.0 for fewer than 2 texts)."""
    from anomalygen.embedding import embed, mean_pairwise_similarity

    if len(texts) < 2:
        return 0.0
    return mean_pairwise_similarity(embed(list(texts)))


def sample_pairs(n: int, max_pairs: int, rng: np.random.Generator) -> list[tuple[int, int]]:
    """All unordered pairs when there are few, else ``max_pairs`` distinct pairs drawn by ``rng``."""
    total = n * (n - 1) // 2
    if total <= max_pairs:
        return list(itertools.combinations(range(n), 2))
    chosen = rng.choice(total, size=max_pairs, replace=False)
    pairs = []
    for k in sorted(int(c) for c in chosen):
        # invert the row-major enumeration of the upper triangle
        i = int(n - 2 - np.floor(np.sqrt(-8 * k + 4 * n * (n - 1) - 7) / 2.0 - 0.5))
        j = int(k + i + 1 - n * (n - 1) // 2 + (n - i) * ((n - i) - 1) // 2)
        pairs.append((i, j))
    return pairs


def _word_piece_bags(texts: Sequence[str]) -> tuple[list[dict[int, float]], np.ndarray]:
    """Per text a normalised bag of word-piece ids, and the unit vectors of every id used."""
    from anomalygen.embedding import encoder

    model = encoder()
    tokenizer = model.tokenizer
    matrix = model[0].auto_model.embeddings.word_embeddings.weight.detach().cpu().numpy()
    bags = []
    for text in texts:
        ids = tokenizer(text, add_special_tokens=False)["input_ids"]
        counts = Counter(ids)
        total = sum(counts.values())
        bags.append({i: c / total for i, c in counts.items()})
    used = sorted({i for bag in bags for i in bag})
    vecs = matrix[used] if used else np.zeros((0, matrix.shape[1]), dtype=np.float32)
    norms = np.linalg.norm(vecs, axis=1, keepdims=True)
    vecs = vecs / np.maximum(norms, 1e-12)
    index = {tok: k for k, tok in enumerate(used)}
    remapped = [{index[i]: w for i, w in bag.items()} for bag in bags]
    return remapped, vecs.astype(np.float64)


def word_movers_distance(a: dict[int, float], b: dict[int, float], vecs: np.ndarray) -> float:
    """Exact WMD between two bags (ids index ``vecs``), cosine ground cost, via POT's ``emd2``."""
    import ot

    if not a or not b:
        return 1.0  # nothing to move: treat an empty text as maximally unlike (cosine distance 1)
    ia, wa = zip(*sorted(a.items()), strict=False)
    ib, wb = zip(*sorted(b.items()), strict=False)
    cost = 1.0 - vecs[list(ia)] @ vecs[list(ib)].T
    np.clip(cost, 0.0, 2.0, out=cost)
    wa_arr = np.asarray(wa, dtype=np.float64)
    wb_arr = np.asarray(wb, dtype=np.float64)
    wa_arr /= wa_arr.sum()
    wb_arr /= wb_arr.sum()
    return float(ot.emd2(wa_arr, wb_arr, cost))


def mean_wmd(texts: Sequence[str], *, rng: np.random.Generator, max_pairs: int = 2000) -> float:
    """Mean pairwise WMD over all pairs, or a seeded sample of ``max_pairs`` pairs when there are more."""
    if len(texts) < 2:
        return 0.0
    bags, vecs = _word_piece_bags(texts)
    pairs = sample_pairs(len(texts), max_pairs, rng)
    return float(np.mean([word_movers_distance(bags[i], bags[j], vecs) for i, j in pairs]))
