"""The catalogue's front door: a procedural asset by name and seed, a scene's draw among the real and
procedural models of a name, the names the catalogue has, and an asset rebuilt from its reference
(procedural, packaged or imported).

The types live in ``model.py``, per-name facts in ``names.py``, the draft -> Asset step in
``finalize.py`` and the registry the generators fill in ``registry.py``; this module sits above the
generators and importers and is the only one that loads them.
"""

from __future__ import annotations

import inspect

from anomalygen.assets.finalize import finalize
from anomalygen.assets.model import Asset
from anomalygen.assets.names import size_range
from anomalygen.assets.registry import GENERATORS
from anomalygen.schema import AssetRef, AssetSource


def _load_generators() -> None:
    from anomalygen.assets.generators import (  # noqa: F401
        appliances,
        devices,
        fixtures,
        furniture,
        household,
        small,
    )


def generate(name: str, seed: int, size: float | None = None) -> Asset:
    """A procedural asset for a vocabulary name; the same (name, seed, size) always gives the same asset.

    A name only a package provides (no generator yet, e.g. ``Stove``) gives its packaged model."""
    from anomalygen.rng import item_rng

    _load_generators()
    if name not in GENERATORS:
        if real_models(name):
            return draw(name, seed, size)
        raise KeyError(f"no generator for {name!r}; known: {', '.join(available_names())}")
    rng = item_rng(seed, "asset", name)
    gen = GENERATORS[name]
    if size is not None and "size" in inspect.signature(gen).parameters:
        # a generator that builds to the requested size itself (a counter grows in length, not in
        # height: scaled uniformly, a 2.3 m counter stood 1.46 m tall, beyond the arm's reach)
        lo, hi = size_range(name)
        draft = gen(rng, size=float(min(hi, max(lo, size))))
    else:
        draft = gen(rng)
    asset = finalize(draft, name=name, seed=seed, size=size, rng=rng)
    if size is not None:
        asset.params["requested_size"] = size
    return asset


def real_models(name: str) -> tuple:
    """The packaged models of a catalogue name (``assets/real/catalogue.py``), in catalogue order."""
    from anomalygen.assets.real.catalogue import by_category

    return by_category().get(name, ())


def draw(name: str, seed: int, size: float | None = None, *, real: bool = True) -> Asset:
    """The asset a scene gets for ``name``: one of its real models (chosen by ``seed``) where the
    catalogue has any and ``real`` is on, else the procedural one. Same arguments, same asset."""
    models = real_models(name) if real else ()
    if models:
        from anomalygen.assets.real.catalogue import build

        return build(models[seed % len(models)], size)
    return generate(name, seed, size)


PROCEDURAL_LICENCE = "MIT"  # the generators are this project's code


def sources(name: str) -> dict:
    """Where ``name``'s models come from: ``sources`` (the procedural generator and each packaged
    model, with package, version and licence), ``licences`` and ``real_models`` (how many)."""
    from anomalygen.assets.real.catalogue import installed

    _load_generators()
    out = []
    if name in GENERATORS:
        out.append({"source": "procedural", "package": "anomalygen", "licence": PROCEDURAL_LICENCE})
    for m in real_models(name):
        out.append({"source": m.package, "model": m.key, "package": m.package,
                    "version": installed(m.package), "licence": m.licence})
    return {"sources": out, "licences": sorted({s["licence"] for s in out}), "real_models": len(real_models(name))}


def available_names() -> list[str]:
    from anomalygen.assets.real.catalogue import by_category

    _load_generators()
    return sorted(set(GENERATORS) | set(by_category()))


def from_ref(ref: AssetRef) -> Asset:
    """Rebuild an asset from its reference (procedural: name + seed + size; packaged: the model key +
    size; imported: the path)."""
    if ref.source == AssetSource.PROCEDURAL:
        return generate(ref.category, int(ref.seed or 0), size=ref.params.get("size"))
    if ref.source == AssetSource.PACKAGED and ref.params.get("model"):
        from anomalygen.assets.real.catalogue import build, by_key

        return build(by_key(str(ref.params["model"])), ref.params.get("size"))
    if ref.source == AssetSource.PARTNET and ref.path:
        from anomalygen.assets.importers import load_partnet

        return load_partnet(ref.path, size=ref.params.get("size"))
    if ref.source == AssetSource.OBJAVERSE and ref.path:
        from anomalygen.assets.importers import load_objaverse

        return load_objaverse(ref.path, size=ref.params.get("size"))
    raise ValueError(f"cannot rebuild asset {ref.asset_id!r} from source {ref.source}")
