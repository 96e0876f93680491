"""Seeded randomness. Every random choice takes an explicit ``numpy.random.Generator``.

Per-item generators are derived from the run seed and the item id (not from call order), so an item
gets the same randomness whether it runs alone, resumed, in a process pool or on Ray.
"""

from __future__ import annotations

import hashlib

import numpy as np


def stable_hash(*keys: object) -> int:
    """A 64-bit hash that, unlike ``hash()``, is identical across processes and machines."""
    digest = hashlib.blake2b("\x1f".join(map(str, keys)).encode(), digest_size=8).digest()
    return int.from_bytes(digest, "little")


def item_rng(seed: int, *keys: object) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence([seed & 0xFFFFFFFF, stable_hash(*keys) & 0xFFFFFFFFFFFFFFFF]))
