"""The generator registry: one procedural generator per vocabulary name (``@register("Name")``)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from anomalygen.assets.model import Draft

Generator = Callable[[np.random.Generator], Draft]
GENERATORS: dict[str, Generator] = {}


def register(*names: str):
    def deco(fn: Generator) -> Generator:
        for n in names:
            GENERATORS[n] = fn
        return fn

    return deco
