"""Materials and small shape recipes shared by the generators.

Materials pair a colour family with a density so masses come out plausible from volumes: solid
primitives stand in for hollow appliances, so those use a low "effective" density.
"""

from __future__ import annotations

import math

import numpy as np

from anomalygen.assets.parts import Part

WOOD = [(0.55, 0.36, 0.2, 1), (0.72, 0.53, 0.33, 1), (0.4, 0.26, 0.15, 1), (0.82, 0.68, 0.5, 1)]
METAL = [(0.75, 0.76, 0.78, 1), (0.55, 0.56, 0.6, 1), (0.3, 0.3, 0.32, 1), (0.85, 0.85, 0.82, 1)]
PLASTIC = [
    (0.85, 0.15, 0.15, 1),
    (0.15, 0.4, 0.85, 1),
    (0.1, 0.65, 0.3, 1),
    (0.95, 0.8, 0.1, 1),
    (0.95, 0.95, 0.95, 1),
    (0.12, 0.12, 0.13, 1),
    (0.95, 0.5, 0.1, 1),
    (0.55, 0.25, 0.7, 1),
]
APPLIANCE = [(0.93, 0.93, 0.93, 1), (0.78, 0.79, 0.8, 1), (0.15, 0.15, 0.16, 1), (0.65, 0.66, 0.68, 1)]
CERAMIC = [(0.96, 0.95, 0.92, 1), (0.85, 0.88, 0.92, 1), (0.7, 0.82, 0.75, 1), (0.9, 0.8, 0.7, 1)]
FABRIC = [
    (0.2, 0.3, 0.55, 1),
    (0.6, 0.15, 0.2, 1),
    (0.3, 0.45, 0.3, 1),
    (0.75, 0.7, 0.6, 1),
    (0.35, 0.35, 0.38, 1),
]
GLASS = (0.75, 0.88, 0.95, 0.45)
DARK = (0.08, 0.08, 0.09, 1)
BLACK_GLASS = (0.05, 0.06, 0.08, 1)
WHITE = (0.96, 0.96, 0.96, 1)

D_WOOD, D_METAL, D_PLASTIC, D_CERAMIC, D_GLASS, D_FOOD, D_FABRIC, D_HOLLOW = (
    600.0,
    7800.0,
    950.0,
    2300.0,
    2500.0,
    900.0,
    250.0,
    250.0,
)


def pick(rng: np.random.Generator, options):
    return options[int(rng.integers(len(options)))]


def colour(rng: np.random.Generator, palette, jitter: float = 0.05):
    c = np.asarray(pick(rng, palette), float)
    c[:3] = np.clip(c[:3] + rng.uniform(-jitter, jitter, 3), 0, 1)
    return tuple(float(v) for v in c)


def u(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(rng.uniform(lo, hi))


def colour_name(rgba) -> str:
    """A coarse colour word for descriptions."""
    r, g, b = rgba[:3]
    if max(r, g, b) < 0.22:
        return "black"
    if min(r, g, b) > 0.85:
        return "white"
    if max(r, g, b) - min(r, g, b) < 0.1:
        return "grey"
    if r > 0.5 and g > 0.4 and b < 0.3 and abs(r - g) < 0.35:
        return "yellow" if g > 0.7 else "brown" if r < 0.75 else "orange"
    hue = ["red", "orange", "yellow", "green", "cyan", "blue", "purple"]
    import colorsys

    h = colorsys.rgb_to_hsv(r, g, b)[0]
    return hue[min(6, int(h * 7))]


def open_box(part: Part, hx, hy, hz, t, rgba, density, *, z0=0.0, top=False, front=True, center=(0.0, 0.0)):
    """A five- or six-sided shell (walls of thickness t) whose interior can hold things.

    Convention for every asset: the front faces -y (doors, drawers, openings), the back is +y.
    ``front=False`` leaves the front face open.
    """
    cx, cy = center
    part.box((hx, hy, t / 2), (cx, cy, z0 + t / 2), rgba, density)  # bottom
    part.box((t / 2, hy, hz), (cx - hx + t / 2, cy, z0 + hz), rgba, density)
    part.box((t / 2, hy, hz), (cx + hx - t / 2, cy, z0 + hz), rgba, density)
    part.box((hx - t, t / 2, hz), (cx, cy + hy - t / 2, z0 + hz), rgba, density)  # back (+y)
    if front:
        part.box((hx - t, t / 2, hz), (cx, cy - hy + t / 2, z0 + hz), rgba, density)
    if top:
        part.box((hx, hy, t / 2), (cx, cy, z0 + 2 * hz - t / 2), rgba, density)


def cable_path(rng: np.random.Generator, length: float, n: int, r: float):
    """Points of a flat, gently wandering cable on the floor (a random walk with smooth turns)."""
    step = length / n
    pts = [np.zeros(3)]
    ang = 0.0
    for _ in range(n):
        ang += float(rng.normal(0, 0.45))
        ang = float(np.clip(ang, -1.2, 1.2))
        pts.append(pts[-1] + step * np.array([math.cos(ang), math.sin(ang), 0.0]))
    return [p + np.array([0, 0, r]) for p in pts]
