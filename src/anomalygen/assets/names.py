"""Per-name facts of the asset vocabulary: the object table, target and household names, sizes, tags."""

from __future__ import annotations

import functools
import json
from importlib import resources
from typing import Any


@functools.cache
def object_table() -> dict[str, tuple[float, float, str, tuple[str, ...]]]:
    raw = json.loads(resources.files("anomalygen.data").joinpath("assets/objects.json").read_text())[
        "objects"
    ]
    return {k: (float(v[0]), float(v[1]), v[2], tuple(v[3].split())) for k, v in raw.items()}


@functools.cache
def vocabulary() -> dict[str, Any]:
    return json.loads(resources.files("anomalygen.data").joinpath("vocabulary.json").read_text())


def target_names() -> list[str]:
    return list(vocabulary()["targets"])


def household_names() -> list[str]:
    return list(vocabulary()["household"])


@functools.cache
def _knowledge_sizes() -> dict[str, tuple[float, float]]:
    """``size_range`` of every object in the knowledge base, the project's single source of sizes."""
    try:
        raw = json.loads(resources.files("anomalygen.data").joinpath("knowledge/objects.json").read_text())
    except (FileNotFoundError, json.JSONDecodeError):
        return {}
    objs = raw.get("objects", {})
    items = objs.items() if isinstance(objs, dict) else ((o.get("name"), o) for o in objs)
    out = {}
    for name, info in items:
        sr = info.get("size_range") if isinstance(info, dict) else None
        if name and sr and len(sr) == 2 and 0 < sr[0] <= sr[1]:
            out[name] = (float(sr[0]), float(sr[1]))
    return out


def size_range(name: str) -> tuple[float, float]:
    """Plausible largest dimension (metres) for a vocabulary name: the knowledge base's
    ``ObjectInfo.size_range`` when it has one, else the asset table's."""
    if name in _knowledge_sizes():
        return _knowledge_sizes()[name]
    try:
        lo, hi, _, _ = object_table()[name]
    except KeyError:
        raise KeyError(f"unknown asset name {name!r}") from None
    return lo, hi


def tags(name: str) -> tuple[str, ...]:
    return object_table()[name][3]


def group(name: str) -> str:
    return object_table()[name][2]
