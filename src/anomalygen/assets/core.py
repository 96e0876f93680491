"""The catalogue's front door: a procedural asset by name and seed, the names there are generators
for, and an asset rebuilt from its reference (procedural or imported).

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
    """A procedural asset for a vocabulary name; the same (name, seed, size) always gives the same asset."""
    from anomalygen.rng import item_rng

    _load_generators()
    if name not in GENERATORS:
        raise KeyError(f"no generator for {name!r}; known: {', '.join(sorted(GENERATORS))}")
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


def available_names() -> list[str]:
    _load_generators()
    return sorted(GENERATORS)


def from_ref(ref: AssetRef) -> Asset:
    """Rebuild an asset from its reference (procedural: name + seed + size; imported: the path)."""
    if ref.source == AssetSource.PROCEDURAL:
        return generate(ref.category, int(ref.seed or 0), size=ref.params.get("size"))
    if ref.source == AssetSource.PARTNET and ref.path:
        from anomalygen.assets.importers import load_partnet

        return load_partnet(ref.path, size=ref.params.get("size"))
    if ref.source == AssetSource.OBJAVERSE and ref.path:
        from anomalygen.assets.importers import load_objaverse

        return load_objaverse(ref.path, size=ref.params.get("size"))
    raise ValueError(f"cannot rebuild asset {ref.asset_id!r} from source {ref.source}")
