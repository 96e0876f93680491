"""Household fixtures the open-world hazards need: stove, sink, bathtub, stairs, bookcase, crib,
curtains and a baby gate.

All are furniture-sized (the scene builder welds them) and face -y. Their moving parts are the
controls and closures a hazard is about: a knob per burner, a tap lever, a gate. Water is a hidden
geom named ``water`` in a basin, drawn by the scene builder when the task fills it.
"""

from __future__ import annotations

import math

from anomalygen.assets.generators.common import (
    APPLIANCE,
    BLACK_GLASS,
    CERAMIC,
    D_FABRIC,
    D_METAL,
    D_WOOD,
    DARK,
    FABRIC,
    METAL,
    PLASTIC,
    WHITE,
    WOOD,
    colour,
    colour_name,
    u,
)
from anomalygen.assets.generators.parts_lib import glow, knob, tap_lever
from anomalygen.assets.model import Cavity, Draft, Surface
from anomalygen.assets.parts import Part, axis_angle
from anomalygen.assets.registry import register
from anomalygen.schema import GATE

WATER = (0.25, 0.5, 0.9, 0.0)  # hidden until the builder fills the basin (``world/states.py``)
WATER_FILL = 0.7  # of a basin's depth
SHELL = 120.0  # kg/m3: a hollow cabinet or staircase modelled as a solid box
TUBE = 1500.0  # kg/m3: a thin-walled metal tube modelled as a solid rod
HIGH_SHELF_TOP = 1.44  # m: the highest a bookcase's high shelf stands
BAR_GAP = 0.06  # m between a crib's or gate's bars (safety standards allow at most 6 cm)


def _water(part: Part, cx, cy, hx, hy, z0, depth) -> None:
    """The hidden water volume of a basin: massless, no collision (things sink to the bottom)."""
    hz = depth * WATER_FILL / 2
    part.box((hx, hy, hz), (cx, cy, z0 + hz), WATER, 0.0, collide=False, name="water")


def _tap(part: Part, x, y, z, reach: float, rgba, direction=(0.0, -1.0)) -> None:
    """A tap column at (x, y) standing on z, its spout reaching ``reach`` along ``direction``, and a
    lever on top (``tap_lever``)."""
    col = 0.16
    part.cyl(0.016, col / 2, (x, y, z + col / 2), rgba, D_METAL)
    end = (x + direction[0] * reach, y + direction[1] * reach, z + col - 0.01)
    part.segment((x, y, z + col - 0.01), end, 0.011, rgba, D_METAL)
    part.segment(end, (end[0], end[1], end[2] - 0.04), 0.009, rgba, D_METAL)
    tap_lever(part, "lever", (x, y, z + col + 0.012), 0.09, rgba)


@register("Stove")
def stove(rng):
    """A freestanding cooktop: four burners on top, one front knob per burner (knob_k turns burner_k)."""
    r = Part("root")
    hx, hy, h = u(rng, 0.3, 0.38), u(rng, 0.28, 0.32), u(rng, 0.86, 0.92)
    body = colour(rng, APPLIANCE)
    top = colour(rng, [BLACK_GLASS, METAL[0], METAL[2]])
    r.box((hx, hy, h / 2 - 0.01), (0, 0, h / 2 - 0.01), body, SHELL)
    r.box((hx, hy, 0.01), (0, 0, h - 0.01), top, 1000)  # the hob plate (glass over a hollow frame)
    fascia = 0.08
    r.box((hx, 0.02, fascia / 2), (0, -hy - 0.02, h - fascia / 2 - 0.02), body, SHELL)
    surfaces = [Surface("cooktop", (0, 0, h), (hx - 0.01, hy - 0.01))]
    big = u(rng, 0.075, 0.095)
    for k, (sx, sy) in enumerate(((-1, -1), (-1, 1), (1, 1), (1, -1))):  # front-left, back-left, ...
        x, y = sx * hx * 0.5, sy * hy * 0.48
        rad = big if k in (0, 2) else big * 0.75
        r.cyl(rad, 0.003, (x, y, h + 0.003), DARK, D_METAL, collide=False)  # burner ring
        r.cyl(rad * 0.45, 0.004, (x, y, h + 0.004), METAL[2], D_METAL, collide=False)  # cap
        glow(r, f"knob_{k}", "cylinder", (rad * 0.9, 0.003), (x, y, h + 0.0042))
        surfaces.append(Surface(f"burner_{k}", (x, y, h), (rad, rad)))
        kx = -hx * 0.75 + hx * 0.5 * k
        knob(r, f"knob_{k}", (kx, -hy - 0.04, h - fascia / 2 - 0.02), 0.02, DARK)
    return Draft(
        r,
        {"burners": 4},
        surfaces,
        [],
        [colour_name(body), "four burners", "a control knob per burner", "hot when a burner is on"],
        front_access=True,
    )


@register("Sink")
def sink(rng):
    """A kitchen sink unit: a worktop with a sunken basin and a lever tap behind it."""
    r = Part("root")
    hx, hy, h = u(rng, 0.4, 0.6), u(rng, 0.28, 0.32), u(rng, 0.86, 0.92)
    bx, by, depth = u(rng, 0.17, 0.24), u(rng, 0.15, 0.18), u(rng, 0.15, 0.2)
    cx = u(rng, -1, 1) * (hx - bx - 0.12)
    cy = -0.03
    body = colour(rng, WOOD + [WHITE, (0.3, 0.35, 0.45, 1)])
    top = colour(rng, [(0.85, 0.84, 0.8, 1), (0.2, 0.2, 0.22, 1), WOOD[3]])
    steel = METAL[0]
    zb = h - depth  # basin bottom
    r.box((hx, hy - 0.02, zb / 2), (0, 0.02, zb / 2), body, SHELL)  # cabinet below the basin
    r.box((hx, 0.003, zb / 2 - 0.06), (0, -hy + 0.015, zb / 2), body, SHELL, collide=False)  # doors
    # worktop around the hole: left, right, front, back blocks down to the basin bottom
    zc, hz = (zb + h) / 2, depth / 2
    r.box(((cx - bx + hx) / 2, hy, hz), ((cx - bx - hx) / 2, 0, zc), top, 400)
    r.box(((hx - cx - bx) / 2, hy, hz), ((cx + bx + hx) / 2, 0, zc), top, 400)
    r.box((bx, (cy - by + hy) / 2, hz), (cx, (cy - by - hy) / 2, zc), top, 400)
    r.box((bx, (hy - cy - by) / 2, hz), (cx, (cy + by + hy) / 2, zc), top, 400)
    for sx in (-1, 1):  # steel lining (decoration)
        r.box((0.001, by, hz), (cx + sx * (bx - 0.001), cy, zc), steel, D_METAL, collide=False)
        r.box((bx, 0.001, hz), (cx, cy + sx * (by - 0.001), zc), steel, D_METAL, collide=False)
    r.box((bx, by, 0.001), (cx, cy, zb + 0.001), steel, D_METAL, collide=False)
    r.cyl(0.025, 0.0015, (cx, cy, zb + 0.002), DARK, D_METAL, collide=False)  # drain
    _water(r, cx, cy, bx - 0.002, by - 0.002, zb + 0.002, depth)
    _tap(r, cx, cy + by + 0.045, h, 0.12, steel)
    surfaces = []
    for side, x0, x1 in (("left", -hx, cx - bx), ("right", cx + bx, hx)):
        if x1 - x0 > 0.16:
            surfaces.append(Surface(f"counter_{side}", ((x0 + x1) / 2, 0, h), ((x1 - x0) / 2 - 0.03, hy - 0.03)))
    basin = Cavity("basin", (cx, cy, zb + depth / 2), (bx - 0.01, by - 0.01, depth / 2 - 0.005), "top", open_above=True)
    return Draft(
        r,
        {"basin_depth": depth},
        surfaces,
        [basin],
        [colour_name(top) + " worktop", "steel basin", "lever tap", "holds water"],
    )


@register("Bathtub")
def bathtub(rng):
    """A bathtub: thick walls around a basin, a wide deck at the tap end (+x) and a lever tap on it."""
    r = Part("root")
    hx, hy, h = u(rng, 0.75, 0.85), u(rng, 0.35, 0.4), u(rng, 0.5, 0.58)
    tw, deck, base = u(rng, 0.06, 0.08), u(rng, 0.26, 0.3), 0.06
    c = colour(rng, CERAMIC[:2] + [WHITE])
    d = 250.0  # acrylic shell over a hollow frame
    r.box((hx, hy, base / 2), (0, 0, base / 2), c, d)
    hz, zc = (h - base) / 2, (h + base) / 2
    for sy in (-1, 1):
        r.box((hx, tw / 2, hz), (0, sy * (hy - tw / 2), zc), c, d)
    r.box((tw / 2, hy - tw, hz), (-hx + tw / 2, 0, zc), c, d)
    r.box((deck / 2, hy - tw, hz), (hx - deck / 2, 0, zc), c, d)
    ix0, ix1, iy = -hx + tw, hx - deck, hy - tw  # inner basin
    _water(r, (ix0 + ix1) / 2, 0, (ix1 - ix0) / 2 - 0.002, iy - 0.002, base, h - base)
    r.cyl(0.025, 0.0015, (ix1 - 0.1, 0, base + 0.002), METAL[0], D_METAL, collide=False)  # drain
    _tap(r, hx - deck / 2, hy * 0.45, h, deck / 2 + 0.06, METAL[0], direction=(-1.0, 0.0))
    surfaces = [Surface("deck", (hx - deck / 2, -hy * 0.3, h), (deck / 2 - 0.01, hy * 0.55))]
    basin = Cavity("basin", ((ix0 + ix1) / 2, 0, (base + h) / 2), ((ix1 - ix0) / 2 - 0.01, iy - 0.01, hz - 0.005), "top",
                   open_above=True)
    return Draft(r, {"length": 2 * hx}, surfaces, [basin], [colour_name(c), "wide deck at the tap end", "lever tap", "holds water"])


@register("Stairs")
def stairs(rng):
    """A short flight: 3-4 solid steps rising to the back (+y), the front step facing the robot."""
    r = Part("root")
    n = int(rng.integers(3, 5))
    hx, rise, tread = u(rng, 0.4, 0.5), u(rng, 0.16, 0.19), u(rng, 0.25, 0.3)
    c = colour(rng, WOOD)
    carpet = colour(rng, FABRIC)
    y0 = -n * tread / 2
    surfaces = []
    for k in range(n):
        top = (k + 1) * rise
        y = y0 + (k + 0.5) * tread
        depth_back = n * tread / 2 - (y - tread / 2)  # each block runs to the back wall
        r.box((hx, depth_back / 2, rise / 2), (0, y - tread / 2 + depth_back / 2, top - rise / 2), c, SHELL)
        r.box((hx * 0.8, tread / 2 - 0.01, 0.002), (0, y, top + 0.002), carpet, D_FABRIC, collide=False)
        surfaces.append(Surface(f"step_{k}", (0, y, top), (hx - 0.03, tread / 2 - 0.03)))
    post = n * rise + 0.85  # a handrail along one side, on posts at the bottom and top steps
    side = hx + 0.03
    for y, top in ((y0 + tread / 2, rise + 0.85), (-y0 - tread / 2, post)):
        r.segment((side, y, 0.0), (side, y, top), 0.02, c, D_WOOD, kind="cylinder")
    r.segment((side, y0 + tread / 2, rise + 0.85), (side, -y0 - tread / 2, post), 0.02, c, D_WOOD)
    return Draft(r, {"steps": n, "rise": rise}, surfaces, [], [f"{n} steps", colour_name(c), "handrail", "fall risk"],
                 front_access=True)


@register("Bookcase")
def bookcase(rng, size=None):
    """A tall bookcase whose high shelf stands 1.40-1.44 m up: out of a child's reach, things there
    fall far, and the arm (which reaches object centres up to 1.45 m) can still get small ones down.
    Its top, another 0.3-0.42 m up, is no shelf. Asked for a ``size`` (its height), it is built that
    tall with its high shelf where it was: scaled, the shelf would rise out of the arm's reach."""
    r = Part("root")
    hx, hy, high = u(rng, 0.35, 0.5), u(rng, 0.14, 0.18), u(rng, 1.4, HIGH_SHELF_TOP)
    t = 0.02
    h = high + u(rng, 0.3, 0.42) + t
    if size is not None:
        h = max(size, high + 0.25 + t)
    n = math.ceil((high - 0.06) / 0.36)  # board spacing at most 0.36 m
    c = colour(rng, WOOD + [WHITE, DARK])
    for sx in (-1, 1):
        r.box((t / 2, hy, h / 2), (sx * (hx - t / 2), 0, h / 2), c, D_WOOD)
    r.box((hx, 0.004, h / 2), (0, hy - 0.004, h / 2), c, D_WOOD)  # back
    r.box((hx, hy, t / 2), (0, 0, h - t / 2), c, D_WOOD)  # top
    r.box((hx - t, 0.01, 0.03), (0, -hy + 0.01, 0.03), c, D_WOOD)  # plinth
    surfaces = []
    for i in range(n + 1):
        z = 0.06 + i * (high - 0.06) / n
        r.box((hx - t, hy - 0.004, t / 2), (0, -0.004, z - t / 2), c, D_WOOD)
        surfaces.append(Surface(f"board_{i}", (0, -0.004, z), (hx - t - 0.01, hy - 0.02)))
    # top down: the boards are alike, and a holder's first largest surface is where "on the bookcase"
    # puts things (``scene/instances.py::surface_of``): the high shelf
    surfaces.reverse()
    return Draft(r, {"boards": n + 1, "high_shelf": round(high, 3)}, surfaces, [],
                 [f"{n + 1} shelves", colour_name(c), "tall", "high shelf"], front_access=True)


def _bars(part: Part, a, b, z0, z1, r_bar, rgba, density) -> None:
    """Vertical bars from z0 to z1 between points a and b (x, y) at most BAR_GAP apart."""
    length = math.dist(a, b)
    n = max(1, math.ceil(length / (BAR_GAP + 2 * r_bar)))
    for i in range(1, n):
        x = a[0] + (b[0] - a[0]) * i / n
        y = a[1] + (b[1] - a[1]) * i / n
        part.capsule(r_bar, (z1 - z0) / 2 - r_bar, (x, y, (z0 + z1) / 2), rgba, density)


@register("Crib")
def crib(rng):
    """A baby's cot: corner posts, rails and bars on all four sides, a mattress inside."""
    r = Part("root")
    hx, hy, h = u(rng, 0.6, 0.7), u(rng, 0.32, 0.37), u(rng, 0.85, 1.0)
    zm = u(rng, 0.3, 0.45)  # mattress top
    c = colour(rng, WOOD + [WHITE])
    mat = colour(rng, [WHITE, (0.8, 0.88, 0.95, 1), (0.95, 0.85, 0.85, 1)])
    p = 0.025
    for sx in (-1, 1):
        for sy in (-1, 1):
            r.box((p, p, h / 2), (sx * (hx - p), sy * (hy - p), h / 2), c, D_WOOD)
    r.box((hx - 2 * p, hy - 2 * p, 0.01), (0, 0, zm - 0.08 - 0.01), c, D_WOOD)  # base board
    r.box((hx - 2 * p, hy - 2 * p, 0.04), (0, 0, zm - 0.04), mat, 150)  # mattress
    corners = [(-hx + p, -hy + p), (hx - p, -hy + p), (hx - p, hy - p), (-hx + p, hy - p)]
    for k in range(4):
        a, b = corners[k], corners[(k + 1) % 4]
        mid = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)
        half = (abs(b[0] - a[0]) / 2 or 0.015, abs(b[1] - a[1]) / 2 or 0.015)
        for z in (zm - 0.02, h - 0.02):  # bottom and top rails
            r.box((half[0], half[1], 0.02), (mid[0], mid[1], z), c, D_WOOD)
        _bars(r, a, b, zm, h - 0.04, 0.011, c, D_WOOD)
    cav = Cavity("inside", (0, 0, (zm + h) / 2), (hx - 2 * p - 0.02, hy - 2 * p - 0.02, (h - zm) / 2 - 0.02), "top",
                 open_above=True)
    surf = Surface("mattress", (0, 0, zm), (hx - 2 * p - 0.03, hy - 2 * p - 0.03))
    return Draft(r, {"mattress_height": zm}, [surf], [cav], [colour_name(c), "barred sides", "mattress"])


@register("Curtains")
def curtains(rng):
    """A curtain hanging from a rail: the rail on two posts with feet, so it stands where a window
    would be. The fabric is pleated panels down to just above the floor."""
    r = Part("root")
    hx, h = u(rng, 0.5, 0.8), u(rng, 1.6, 2.2)
    c = colour(rng, FABRIC + [WHITE, (0.9, 0.85, 0.7, 1)])
    pole = METAL[2] if rng.random() < 0.5 else WOOD[2]
    for sx in (-1, 1):
        r.box((0.03, 0.18, 0.015), (sx * (hx + 0.03), 0, 0.015), pole, 2500)  # foot
        r.cyl(0.015, h / 2, (sx * (hx + 0.03), 0, h / 2), pole, TUBE)
    r.cyl(0.015, hx + 0.06, (0, 0, h - 0.02), pole, TUBE, axis="x")  # rail
    n = int(rng.integers(8, 13))
    w = 2 * hx / n
    zt, zbot = h - 0.05, 0.03
    for i in range(n):  # pleats: narrow panels turned alternately
        x = -hx + w * (i + 0.5)
        q = axis_angle((0, 0, 1), 0.45 if i % 2 else -0.45)
        r.box((w / 2 / math.cos(0.45), 0.006, (zt - zbot) / 2), (x, 0, (zt + zbot) / 2), c, D_FABRIC, quat=q)
        r.cyl(0.012, 0.004, (x, 0, h - 0.02), pole, D_METAL, axis="y", collide=False)  # ring
    return Draft(r, {"width": 2 * hx, "height": h}, [], [], [colour_name(c), "long fabric curtain", "on a rail", "flammable"])


@register("BabyGate")
def baby_gate(rng):
    """A free-standing safety gate: two framed posts with feet and a barred gate hinged at the left
    post (label "gate", closed at 0, swinging open to the front)."""
    r = Part("root")
    hx, h = u(rng, 0.38, 0.47), u(rng, 0.7, 0.8)
    c = colour(rng, [WHITE, (0.85, 0.85, 0.85, 1), PLASTIC[5], WOOD[3]])
    p = 0.02
    for sx in (-1, 1):
        r.box((p, p, h / 2), (sx * (hx - p), 0, h / 2), c, D_WOOD)
        r.box((p, 0.15, 0.012), (sx * (hx - p), 0, 0.012), c, D_WOOD)  # foot
    r.box((hx, p, 0.008), (0, 0, 0.008), c, D_WOOD)  # threshold bar
    x0, x1 = -hx + 2 * p, hx - 2 * p
    gate = r.child("gate", (x0, 0, 0))
    gate.hinge("gate_hinge", (0, 0, 1), (-1.7, 0), GATE, 0.0)
    w = x1 - x0 - 0.006
    for z in (0.04, h - 0.04):
        gate.box((w / 2, 0.012, 0.015), (w / 2, 0, z), c, D_WOOD)
    for sx in (0.012, w - 0.012):
        gate.box((0.012, 0.012, (h - 0.08) / 2), (sx, 0, h / 2), c, D_WOOD)
    _bars(gate, (0.012, 0.0), (w - 0.012, 0.0), 0.055, h - 0.055, 0.008, c, D_WOOD)
    gate.box((0.015, 0.02, 0.03), (w - 0.03, -0.025, h - 0.08), DARK, 900)  # latch handle
    return Draft(r, {"width": 2 * hx}, [], [], [colour_name(c), "barred gate on a hinge", "latch"])
