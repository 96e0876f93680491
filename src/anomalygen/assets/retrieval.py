"""The asset catalogue and Sentence-BERT retrieval over it.

The catalogue is a list of (name, seed) variants with their descriptions; it is deterministic, so its
hash identifies the embeddings. An entry's vector combines the embedding of what every variant of its
name shares (``base_text``: what it is, its hazards; embedded once per name) with the embedding of its
short variant text (size, look, moving parts; no per-axis dimensions). Embedding cost grows with
tokens, and this embeds far fewer tokens than the full descriptions would. Embeddings are cached in
memory and on disk (``$ANOMALYGEN_CACHE_DIR`` or ``~/.cache/anomalygen/asset_embeddings/<hash>.npy``), so a scene builder
retrieving for hundreds of tasks embeds the catalogue once.
"""

from __future__ import annotations

import functools
import hashlib
import os
import threading
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class CatalogueEntry:
    asset_id: str
    name: str
    category: str
    description: str
    seed: int
    kind: str  # target | household
    size: float
    properties: tuple[str, ...] = field(default_factory=tuple)
    base_text: str = ""
    variant_text: str = ""


@functools.cache
def _entries(variants_per_name: int) -> tuple[CatalogueEntry, ...]:
    from anomalygen.assets.core import generate
    from anomalygen.assets.describe import base_text, properties, variant_text
    from anomalygen.assets.names import household_names, target_names

    out = []
    targets = set(target_names())
    for name in target_names() + household_names():
        for seed in range(variants_per_name):
            a = generate(name, seed)
            out.append(
                CatalogueEntry(
                    a.asset_id,
                    name,
                    a.category,
                    a.description,
                    seed,
                    "target" if name in targets else "household",
                    round(a.size, 4),
                    tuple(properties(name, a.size)),
                    base_text(name),
                    variant_text(name, a, a.features, dims=False),
                )
            )
    return tuple(out)


def catalogue(variants_per_name: int = 3) -> list[CatalogueEntry]:
    """Every vocabulary name in ``variants_per_name`` seeded variants (seeds 0..n-1)."""
    return list(_entries(int(variants_per_name)))


def catalogue_hash(entries: list[CatalogueEntry]) -> str:
    h = hashlib.blake2b(digest_size=10)
    for e in entries:
        h.update(f"{e.asset_id}\x1f{e.description}\x1f{e.base_text}\x1f{e.variant_text}\x1e".encode())
    return h.hexdigest()


def cache_dir() -> Path:
    base = os.environ.get("ANOMALYGEN_CACHE_DIR")
    return Path(base) if base else Path.home() / ".cache" / "anomalygen"


_MEM: dict[str, np.ndarray] = {}
_LOCK = threading.Lock()


def embeddings(entries: list[CatalogueEntry]) -> np.ndarray:
    """Unit embeddings of the entries' descriptions, from memory, disk, or freshly computed."""
    from anomalygen.embedding import embed
    from anomalygen.runfolder import atomic_write_bytes

    key = catalogue_hash(entries)
    with _LOCK:
        if key in _MEM:
            return _MEM[key]
        path = cache_dir() / "asset_embeddings" / f"{key}.npy"
        vecs = None
        if path.exists():
            try:
                vecs = np.load(path)
                if vecs.shape != (len(entries), 384):
                    vecs = None
            except (OSError, ValueError):
                vecs = None
        if vecs is None:
            vecs = _embed_entries(entries, embed)
            import io

            buf = io.BytesIO()
            np.save(buf, vecs)
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
                atomic_write_bytes(path, buf.getvalue())
            except OSError:
                pass  # a read-only home is no reason to fail retrieval
        _MEM[key] = vecs
        return vecs


BASE_WEIGHT = 0.5  # share of the name-level text in an entry's vector


def _embed_entries(entries: list[CatalogueEntry], embed) -> np.ndarray:
    """Per-name base vectors (embedded once) blended with per-variant vectors, renormalised.
    Entries without split texts (e.g. imported assets) embed their full description."""
    split = [e for e in entries if e.base_text and e.variant_text]
    bases = sorted({e.base_text for e in split})
    base_vec = dict(zip(bases, embed(bases), strict=True)) if bases else {}
    var_vecs = embed([e.variant_text if (e.base_text and e.variant_text) else e.description for e in entries])
    out = np.empty_like(var_vecs)
    for i, e in enumerate(entries):
        v = var_vecs[i]
        if e.base_text and e.variant_text:
            v = BASE_WEIGHT * base_vec[e.base_text] + (1 - BASE_WEIGHT) * v
        out[i] = v / max(float(np.linalg.norm(v)), 1e-12)
    return out.astype(np.float32)


def search(
    query: str, entries: list[CatalogueEntry], k: int = 5, category: str | None = None
) -> list[tuple[CatalogueEntry, float]]:
    """Top-k entries by cosine similarity; optional filter by category (or group name)."""
    from anomalygen.embedding import embed

    if k <= 0 or not entries:
        return []
    vecs = embeddings(entries)
    q = embed([query])[0]
    sims = vecs @ q
    idx = np.arange(len(entries))
    if category is not None:
        want = category.lower()
        idx = np.array(
            [i for i, e in enumerate(entries) if e.category.lower() == want or e.name.lower() == want],
            dtype=int,
        )
        if len(idx) == 0:
            return []
    order = idx[np.argsort(-sims[idx], kind="stable")][:k]
    return [(entries[i], float(sims[i])) for i in order]


def retrieve(
    query: str,
    k: int = 5,
    category: str | None = None,
    *,
    variants_per_name: int = 3,
    distinct_names: bool = True,
) -> list[tuple[CatalogueEntry, float]]:
    """Top-k catalogue assets for a text query. With ``distinct_names`` each name appears once (its
    best variant), so "something a toddler could choke on" returns five kinds of thing, not five
    marbles."""
    entries = catalogue(variants_per_name)
    if not distinct_names:
        return search(query, entries, k, category)
    hits = search(query, entries, len(entries), category)
    seen, out = set(), []
    for e, s in hits:
        if e.name in seen:
            continue
        seen.add(e.name)
        out.append((e, s))
        if len(out) == k:
            break
    return out
