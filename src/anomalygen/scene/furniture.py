"""Support furniture the scene builder adds when a placement needs a raised surface.

Tables, low tables, counters and wall shelves are built here from boxes rather than taken from the
asset catalogue because the hazard predicates depend on exact top heights (the knowledge base's
``SUPPORT_HEIGHTS``: a low table is 0.35-0.5 m, a counter 0.85-0.95 m, ...); a catalogue asset is
scaled by its largest dimension, which does not control its height. Each support is a plain record
(size, top height) plus a function that emits it into an MjSpec body, so placement can reason about it
without compiling.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# Heights the knowledge base expects (top of the surface, metres); used when it is not importable.
DEFAULT_HEIGHTS = {
    "low_table": (0.35, 0.5),
    "table": (0.7, 0.8),
    "counter": (0.85, 0.95),
    "shelf": (1.2, 1.3),  # lower end of the KB's 1.2-1.6 m so the arm still reaches it
}
# Catalogue category each support reports in the scene graph.
CATEGORY = {"low_table": "Table", "table": "Table", "counter": "counter", "shelf": "shelf"}


@dataclass(frozen=True)
class Support:
    """A box-built support: footprint ``half`` (x, y) centred on its origin, top at ``top``."""

    kind: str  # low_table | table | counter | shelf
    half: tuple[float, float]
    top: float
    thickness: float

    @property
    def category(self) -> str:
        return CATEGORY[self.kind]

    @property
    def bottom(self) -> float:
        """Lowest point (a wall shelf hangs; everything else stands on the floor)."""
        return self.top - 0.28 if self.kind == "shelf" else 0.0

    @property
    def size(self) -> float:
        return float(max(2 * self.half[0], 2 * self.half[1], self.top - self.bottom))

    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        return (
            np.array([-self.half[0], -self.half[1], self.bottom]),
            np.array([self.half[0], self.half[1], self.top]),
        )


#: Half extents (depth, width ranges, m) and board thickness of each support kind's top.
TOPS: dict[str, tuple[tuple[float, float], tuple[float, float], float]] = {
    "shelf": ((0.13, 0.18), (0.35, 0.5), 0.03),
    "counter": ((0.28, 0.32), (0.5, 0.7), 0.04),
    "low_table": ((0.25, 0.35), (0.35, 0.5), 0.03),
    "table": ((0.35, 0.45), (0.45, 0.6), 0.035),
}


def largest_top(kind: str) -> tuple[float, float]:
    """The largest (width, depth) a support kind's top is drawn with (m): what brainstorming may
    put on it (``brainstorm/drawable.py``)."""
    (_, dhi), (_, whi), _ = TOPS.get(kind, TOPS["table"])
    return 2 * whi, 2 * dhi


def sample_support(kind: str, rng: np.random.Generator) -> Support:
    lo, hi = _heights().get(kind, DEFAULT_HEIGHTS[kind])
    if kind == "shelf":
        hi = min(hi, DEFAULT_HEIGHTS["shelf"][1])
        lo = min(lo, hi)
    top = float(rng.uniform(lo, hi))
    (dlo, dhi), (wlo, whi), thickness = TOPS.get(kind, TOPS["table"])
    half = (float(rng.uniform(dlo, dhi)), float(rng.uniform(wlo, whi)))
    return Support(kind, half, top, thickness)


def _heights() -> dict[str, tuple[float, float]]:
    try:
        from anomalygen.knowledge.models import SUPPORT_HEIGHTS
    except ImportError:  # pragma: no cover - knowledge package absent
        return DEFAULT_HEIGHTS
    return dict(SUPPORT_HEIGHTS)


def emit(support: Support, body, rng: np.random.Generator) -> None:
    """Add the support's geoms to ``body`` (an MjsBody at floor level, centred on the footprint)."""
    import mujoco

    box = mujoco.mjtGeom.mjGEOM_BOX
    hx, hy, top, th = support.half[0], support.half[1], support.top, support.thickness
    wood = [float(v) for v in (0.55 + 0.2 * rng.random(), 0.4 + 0.15 * rng.random(), 0.28, 1.0)]
    body.add_geom(
        name=f"{body.name}/top",
        type=box,
        size=[hx, hy, th / 2],
        pos=[0, 0, top - th / 2],
        rgba=wood,
        density=600,
    )
    if support.kind == "counter":
        # Solid cabinet under the worktop, slightly recessed so the top has an overhanging edge.
        h = (top - th) / 2
        body.add_geom(
            type=box,
            size=[hx - 0.03, hy - 0.01, h],
            pos=[-0.01, 0, h],
            rgba=[0.85, 0.85, 0.82, 1],
            density=300,
        )
    elif support.kind == "shelf":
        # A wall-mounted plank with two brackets against a back panel (fixed in the world).
        body.add_geom(
            type=box,
            size=[0.01, hy, 0.14],
            pos=[hx + 0.01, 0, top - 0.14],
            rgba=[0.8, 0.8, 0.8, 1],
            density=600,
        )
        for s in (-1, 1):
            body.add_geom(
                type=box,
                size=[hx * 0.8, 0.01, 0.05],
                pos=[0.0, s * (hy - 0.03), top - th - 0.05],
                rgba=wood,
                density=600,
            )
    else:
        leg_h = (top - th) / 2
        for sx in (-1, 1):
            for sy in (-1, 1):
                body.add_geom(
                    type=box,
                    size=[0.025, 0.025, leg_h],
                    pos=[sx * (hx - 0.04), sy * (hy - 0.04), leg_h],
                    rgba=wood,
                    density=600,
                )
