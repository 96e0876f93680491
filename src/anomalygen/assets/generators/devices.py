"""Loose things the open-world hazards need: a space heater and a power strip with on/off controls,
and soft flammables (paper towels, a folded blanket) and a wet patch on the floor.

Controls follow the catalogue's convention: off is the joint's closed value at 0, so a device built
without a task asking for "on" is off.
"""

from __future__ import annotations

import numpy as np

from anomalygen.assets.generators.common import (
    APPLIANCE,
    D_FABRIC,
    D_HOLLOW,
    D_METAL,
    D_PLASTIC,
    DARK,
    FABRIC,
    METAL,
    PLASTIC,
    WHITE,
    colour,
    colour_name,
    u,
)
from anomalygen.assets.generators.parts_lib import glow, knob, push_switch
from anomalygen.assets.model import Draft
from anomalygen.assets.parts import Part
from anomalygen.assets.registry import register
from anomalygen.schema import DIAL, SWITCH

SWITCH_RED = (0.85, 0.1, 0.1, 1)


@register("SpaceHeater")
def space_heater(rng):
    """A fan heater: a box on two feet, a grille in front and a thermostat dial (label "knob")."""
    r = Part("root")
    hx, hy, h = u(rng, 0.1, 0.15), u(rng, 0.07, 0.1), u(rng, 0.28, 0.45)
    c = colour(rng, APPLIANCE[:2] + [DARK, (0.85, 0.82, 0.75, 1)])
    for sx in (-1, 1):
        r.box((0.02, hy + 0.04, 0.01), (sx * (hx - 0.03), 0, 0.01), DARK, D_PLASTIC)  # feet
    r.box((hx, hy, h / 2 - 0.01), (0, 0, h / 2 + 0.01), c, D_HOLLOW)
    gz0, gz1 = 0.05, h * 0.72
    for i in range(6):  # grille bars (decoration)
        z = gz0 + (gz1 - gz0) * (i + 0.5) / 6
        r.box((hx * 0.8, 0.002, 0.004), (0, -hy - 0.002, z), DARK, D_METAL, collide=False)
    glow(r, DIAL, "box", (hx * 0.75, 0.001, (gz1 - gz0) / 2), (0, -hy - 0.0005, (gz0 + gz1) / 2))
    knob(r, "dial", (hx * 0.5, -hy, h * 0.86), 0.018, DARK)
    return Draft(r, {"height": h}, [], [], [colour_name(c), "front grille", "thermostat dial", "hot when on"],
                 front_access=True)


@register("PowerStrip")
def power_strip(rng):
    """A multi-socket strip with a lit push switch at one end (proud when on) and a short lead."""
    r = Part("root")
    n = int(rng.integers(3, 7))
    hx, hy, hz = 0.025 * n + 0.04, u(rng, 0.026, 0.034), u(rng, 0.017, 0.022)
    c = colour(rng, [WHITE, PLASTIC[5]])
    r.box((hx, hy, hz), (0, 0, hz), c, D_PLASTIC * 0.6)
    for k in range(n):  # sockets (decoration)
        x = -hx + 0.03 + 0.05 * k + 0.025
        r.cyl(0.017, 0.0008, (x, 0, 2 * hz + 0.0008), DARK if c[0] > 0.5 else METAL[1], 1, collide=False)
    lead = u(rng, 0.08, 0.15)
    r.segment((-hx, 0, 0.004), (-hx - lead, 0.01, 0.004), 0.004, DARK, 1200, kind="cylinder")
    push_switch(r, "switch", (hx - 0.025, 0, 2 * hz + 0.002), (0.008, 0.012, 0.004), SWITCH_RED)
    glow(r, SWITCH, "box", (0.005, 0.008, 0.0008), (hx - 0.045, 0, 2 * hz + 0.0008))
    return Draft(r, {"sockets": n}, [], [], [colour_name(c), f"{n} sockets", "on/off switch", "power lead"])


@register("PaperTowels")
def paper_towels(rng):
    """A kitchen roll standing on end: a paper cylinder around a cardboard core."""
    r = Part("root")
    rad, h = u(rng, 0.05, 0.065), u(rng, 0.2, 0.28)
    paper = colour(rng, [WHITE, (0.95, 0.95, 0.9, 1)], jitter=0.02)
    r.cyl(rad, h / 2, (0, 0, h / 2), paper, 180)
    r.cyl(0.02, 0.001, (0, 0, h + 0.001), (0.6, 0.45, 0.3, 1), 1, collide=False)  # core end
    return Draft(r, {"height": h}, [], [], ["kitchen roll", "paper, catches fire easily"])


@register("Blanket")
def blanket(rng):
    """A folded blanket: a soft thick slab with a contrasting border."""
    r = Part("root")
    hx, hy, hz = u(rng, 0.17, 0.24), u(rng, 0.13, 0.18), u(rng, 0.03, 0.06)
    c = colour(rng, FABRIC + [WHITE])
    r.box((hx, hy, hz), (0, 0, hz), c, D_FABRIC * 0.6)
    r.box((hx + 0.001, hy * 0.15, hz * 0.6), (0, -hy * 0.7, hz), colour(rng, FABRIC), 1, collide=False)
    return Draft(r, {"length": 2 * hx}, [], [], [colour_name(c), "folded", "soft wool, catches fire easily"])


@register("Puddle")
def puddle(rng):
    """A wet patch on the floor: a thin translucent blue film (slippery; water near electricity)."""
    r = Part("root")
    water = (0.45, 0.65, 0.95, 0.45)
    rad = u(rng, 0.12, 0.22)
    r.cyl(rad, 0.0015, (0, 0, 0.0015), water, 1000)
    for _ in range(int(rng.integers(1, 4))):  # lobes: an irregular outline, still flat on the floor
        a, d = u(rng, 0, 6.28), u(rng, 0.4, 0.8) * rad
        r.cyl(u(rng, 0.4, 0.7) * rad, 0.0015, (d * np.cos(a), d * np.sin(a), 0.0015), water, 1000)
    return Draft(r, {"radius": rad}, [], [], ["spilled water", "wet and slippery"])
