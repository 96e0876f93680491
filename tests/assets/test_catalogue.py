"""Catalogue and Sentence-BERT retrieval (real embeddings, offline), with the on-disk cache."""

from __future__ import annotations

import pytest

from anomalygen.assets import catalogue as catalogue_fn
from anomalygen.assets.retrieval import catalogue, catalogue_hash, embeddings, retrieve


@pytest.fixture()
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("ANOMALYGEN_CACHE_DIR", str(tmp_path))
    from anomalygen.assets import retrieval as mod

    mod._MEM.clear()
    return tmp_path


def test_catalogue_lists_every_name_in_variants():
    entries = catalogue_fn(2)
    assert len(entries) == 2 * 115  # 44 targets, 70 household objects and the Stove
    assert {e.seed for e in entries} == {0, 1}
    pill = next(e for e in entries if e.name == "pill")
    assert "choking_size" in pill.properties and "medication" in pill.properties and pill.kind == "household"


def test_choking_query_returns_small_objects_and_cache_is_reused(cache, monkeypatch):
    hits = retrieve("something a toddler could choke on", 5, variants_per_name=1)
    assert len(hits) == 5 and len({e.name for e, _ in hits}) == 5
    assert all(e.size <= 0.15 for e, _ in hits)
    assert sum("choking_size" in e.properties for e, _ in hits) >= 3
    files = list((cache / "asset_embeddings").glob("*.npy"))
    assert len(files) == 1 and files[0].stem == catalogue_hash(catalogue(1))
    # a fresh process (empty memory cache) reads the file instead of re-embedding the catalogue
    from anomalygen.assets import retrieval as mod

    mod._MEM.clear()
    calls = []
    import anomalygen.embedding as emb

    real = emb.embed
    monkeypatch.setattr(emb, "embed", lambda texts, **kw: calls.append(len(texts)) or real(texts, **kw))
    embeddings(catalogue(1))
    assert calls == []


def test_sharp_query_and_category_filter(cache):
    names = [e.name for e, _ in retrieve("sharp kitchen tool", 5, variants_per_name=1)]
    assert "kitchen_knife" in names
    only = retrieve("open door", 3, "Refrigerator", variants_per_name=1)
    assert only and all(e.name == "Refrigerator" for e, _ in only)
    assert retrieve("anything", 3, "NoSuchThing", variants_per_name=1) == []
