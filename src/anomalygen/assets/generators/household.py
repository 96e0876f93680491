"""Rigid household objects that hazard scenes need (pills, knives, cables, food, toys, ...).

Each generator draws proportions and materials from the seeded generator and builds the object lying
or standing the way it would rest on a floor or table. Absolute size is set later by ``finalize``.
"""

from __future__ import annotations

import math

import numpy as np

from anomalygen.assets.generators.common import (
    CERAMIC,
    D_CERAMIC,
    D_FOOD,
    D_GLASS,
    D_METAL,
    D_WOOD,
    DARK,
    FABRIC,
    GLASS,
    METAL,
    PLASTIC,
    WHITE,
    WOOD,
    cable_path,
    colour,
    colour_name,
    open_box,
    pick,
    u,
)
from anomalygen.assets.generators.parts_lib import glow, push_switch
from anomalygen.assets.model import Cavity, Draft, Surface
from anomalygen.assets.parts import Part, axis_angle
from anomalygen.assets.registry import register
from anomalygen.schema import DOOR, LID, SWITCH
from anomalygen.schema.part_labels import HANDLE_GEOM


def _d(root, features=(), **params):
    return Draft(root, params=params, features=list(features))


# ----------------------------------------------------------------------------- medication, chemicals


@register("pill")
def pill(rng):
    r = Part("root")
    c = colour(rng, [(0.97, 0.97, 0.95, 1), (0.95, 0.7, 0.75, 1), (0.95, 0.9, 0.5, 1), (0.6, 0.75, 0.95, 1)])
    shape = pick(rng, ["capsule", "tablet"])
    if shape == "capsule":
        rad = u(rng, 0.0028, 0.0035)
        r.capsule(rad, u(rng, 0.003, 0.005), (0, 0, rad), c, 1200, axis="x")
    else:
        rad = u(rng, 0.004, 0.006)
        r.cyl(rad, 0.0018, (0, 0, 0.0018), c, 1200)
    return _d(r, [colour_name(c), shape], shape=shape)


@register("pill_bottle")
def pill_bottle(rng):
    r = Part("root")
    rad, h = u(rng, 0.016, 0.024), u(rng, 0.05, 0.085)
    body = pick(rng, [(0.9, 0.5, 0.1, 0.85), (0.95, 0.95, 0.95, 1), (0.35, 0.2, 0.1, 0.9)])
    r.cyl(rad, h / 2, (0, 0, h / 2), body, 400)
    r.cyl(rad * 1.08, 0.008, (0, 0, h + 0.008), WHITE, 900)
    r.cyl(rad * 0.9, 0.0005, (0, -0.0, h * 0.5), WHITE, 900, collide=False)
    return _d(r, ["child-resistant cap", "contains pills"], radius=rad, height=h)


@register("blister_pack")
def blister_pack(rng):
    r = Part("root")
    nx, ny = int(rng.integers(2, 6)), 2
    hx, hy = 0.01 * nx + 0.008, 0.022
    r.box((hx, hy, 0.0008), (0, 0, 0.0008), METAL[0], 2700)
    c = colour(rng, [WHITE, (0.95, 0.8, 0.8, 1)])
    for i in range(nx):
        for j in range(ny):
            r.ellipsoid((0.005, 0.005, 0.0025), (-hx + 0.013 + 0.02 * i, -0.011 + 0.022 * j, 0.0016), c, 1000)
    return _d(r, [f"{nx * ny} tablets"], tablets=nx * ny)


@register("cleaning_spray")
def cleaning_spray(rng):
    r = Part("root")
    c = colour(rng, PLASTIC)
    bw, bd, bh = u(rng, 0.04, 0.055), u(rng, 0.025, 0.035), u(rng, 0.14, 0.19)
    r.box((bw, bd, bh / 2), (0, 0, bh / 2), c, 500)
    r.cyl(0.012, 0.012, (0, 0, bh + 0.012), WHITE, 700)
    head = colour(rng, PLASTIC)
    r.box((0.018, 0.035, 0.022), (0, -0.01, bh + 0.045), head, 700)
    r.box((0.008, 0.006, 0.02), (0, -0.03, bh + 0.012), head, 700)  # trigger
    return _d(r, [colour_name(c), "trigger sprayer"], height=bh)


@register("bleach_bottle")
def bleach_bottle(rng):
    r = Part("root")
    w, d, h = u(rng, 0.05, 0.07), u(rng, 0.04, 0.05), u(rng, 0.18, 0.24)
    c = colour(rng, [WHITE, (0.85, 0.9, 0.95, 1), (0.9, 0.85, 0.3, 1)])
    r.box((w, d, h / 2), (0, 0, h / 2), c, 600)
    r.cyl(0.016, 0.012, (w * 0.5, 0, h + 0.012), pick(rng, PLASTIC), 800)
    r.segment((-w * 0.6, 0, h * 0.95), (-w * 0.6, 0, h * 0.6), 0.008, c, 600)
    r.segment((-w * 0.6, 0, h * 0.95), (-w * 0.1, 0, h + 0.002), 0.008, c, 600)
    return _d(r, ["jug with a handle", "screw cap"], height=h)


@register("detergent_pod")
def detergent_pod(rng):
    r = Part("root")
    a, b, c = u(rng, 0.017, 0.021), u(rng, 0.015, 0.018), u(rng, 0.008, 0.011)
    col = colour(rng, [(0.2, 0.45, 0.95, 1), (0.95, 0.45, 0.1, 1), (0.4, 0.85, 0.4, 1)])
    r.ellipsoid((a, b, c), (0, 0, c), col, 1050)
    r.ellipsoid(
        (a * 0.6, b * 0.5, c * 0.5), (a * 0.2, 0, c * 1.6), (0.95, 0.95, 0.95, 0.9), 1050, collide=False
    )
    return _d(r, ["bright colourful capsule that looks like candy"], size=a)


# ----------------------------------------------------------------------------- tableware


def _vessel(r: Part, rad, h, t, rgba, density, n=12, bottom=None):
    bottom = bottom if bottom is not None else t
    r.cyl(rad, bottom / 2, (0, 0, bottom / 2), rgba, density)
    r.ring(rad - t / 2, bottom, h, t, n, rgba, density)


@register("cup")
def cup(rng):
    r = Part("root")
    rad, h = u(rng, 0.035, 0.045), u(rng, 0.08, 0.11)
    c = colour(rng, PLASTIC + CERAMIC)
    _vessel(r, rad, h, 0.004, c, 1000)
    return Draft(
        r,
        {"radius": rad},
        [],
        [Cavity("inside", (0, 0, h / 2), (rad * 0.7, rad * 0.7, h / 2 - 0.005), "top")],
        [colour_name(c)],
    )


def _mug(rng, hot: bool):
    r = Part("root")
    rad, h = u(rng, 0.038, 0.045), u(rng, 0.085, 0.105)
    c = colour(rng, CERAMIC + PLASTIC[:3])
    _vessel(r, rad, h, 0.005, c, D_CERAMIC)
    hx = rad + 0.018
    r.segment((rad, 0, h * 0.8), (hx, 0, h * 0.75), 0.0055, c, D_CERAMIC)
    r.segment((hx, 0, h * 0.75), (hx, 0, h * 0.3), 0.0055, c, D_CERAMIC)
    r.segment((hx, 0, h * 0.3), (rad, 0, h * 0.25), 0.0055, c, D_CERAMIC)
    feats = [colour_name(c), "handle"]
    if hot:
        r.cyl(rad - 0.006, 0.002, (0, 0, h * 0.8), (0.3, 0.17, 0.08, 1), 1000, collide=False)
        feats += ["full of steaming hot coffee or tea"]
    return Draft(
        r,
        {"radius": rad},
        [],
        [Cavity("inside", (0, 0, h / 2), (rad * 0.7, rad * 0.7, h / 2 - 0.006), "top")],
        feats,
    )


register("mug")(lambda rng: _mug(rng, False))
register("hot_mug")(lambda rng: _mug(rng, True))


@register("plate")
def plate(rng):
    r = Part("root")
    rad = u(rng, 0.1, 0.13)
    c = colour(rng, CERAMIC)
    r.cyl(rad * 0.6, 0.003, (0, 0, 0.003), c, 1500)
    r.cyl(rad, 0.003, (0, 0, 0.009), c, 1500)
    r.cyl(
        rad * 0.65,
        0.0035,
        (0, 0, 0.0095),
        (c[0] * 0.95, c[1] * 0.95, c[2] * 0.95, 1),
        D_CERAMIC,
        collide=False,
    )
    return Draft(
        r, {"radius": rad}, [Surface("top", (0, 0, 0.012), (rad * 0.5, rad * 0.5))], [], [colour_name(c)]
    )


@register("bowl")
def bowl(rng):
    r = Part("root")
    rad, h = u(rng, 0.06, 0.09), u(rng, 0.045, 0.07)
    c = colour(rng, CERAMIC + PLASTIC[:2])
    r.cyl(rad * 0.55, 0.003, (0, 0, 0.003), c, D_CERAMIC)
    n = 14
    for i in range(n):  # flared wall: tilted boxes
        a = 2 * math.pi * i / n
        rr = (rad * 0.55 + rad) / 2
        q = axis_angle((math.cos(a + math.pi / 2), math.sin(a + math.pi / 2), 0), 0.45)
        from anomalygen.assets.parts import quat_mul

        q = quat_mul(q, axis_angle((0, 0, 1), a))
        r.box(
            (0.0025, math.pi * rad / n * 1.1, h / 2),
            (rr * math.cos(a), rr * math.sin(a), h / 2 + 0.002),
            c,
            D_CERAMIC,
            quat=q,
        )
    return Draft(
        r,
        {"radius": rad},
        [],
        [Cavity("inside", (0, 0, h / 2), (rad * 0.5, rad * 0.5, h / 2 - 0.004), "top")],
        [colour_name(c)],
    )


@register("glass")
def glass(rng):
    r = Part("root")
    rad, h = u(rng, 0.03, 0.04), u(rng, 0.09, 0.14)
    _vessel(r, rad, h, 0.003, GLASS, D_GLASS, bottom=0.01)
    return Draft(
        r,
        {"radius": rad},
        [],
        [Cavity("inside", (0, 0, h / 2 + 0.005), (rad * 0.7, rad * 0.7, h / 2 - 0.01), "top")],
        ["transparent glass"],
    )


@register("wine_glass")
def wine_glass(rng):
    r = Part("root")
    foot, stem, bowl_h, rad = u(rng, 0.032, 0.04), u(rng, 0.06, 0.09), u(rng, 0.07, 0.1), u(rng, 0.035, 0.045)
    r.cyl(foot, 0.003, (0, 0, 0.003), GLASS, D_GLASS)
    r.cyl(0.004, stem / 2, (0, 0, stem / 2 + 0.006), GLASS, D_GLASS)
    r.cyl(rad * 0.5, 0.004, (0, 0, stem + 0.01), GLASS, D_GLASS)
    r.ring(rad, stem + 0.014, stem + 0.014 + bowl_h, 0.0025, 12, GLASS, D_GLASS)
    return _d(r, ["stemmed", "thin glass"], stem=stem)


# ----------------------------------------------------------------------------- cutlery, kitchen


@register("fork")
def fork(rng):
    r = Part("root")
    L = u(rng, 0.18, 0.2)
    c = pick(rng, METAL[:2])
    r.box((L * 0.32, 0.007, 0.002), (-L * 0.18, 0, 0.002), c, D_METAL)
    r.box((L * 0.08, 0.012, 0.0015), (L * 0.2, 0, 0.0025), c, D_METAL)
    for k in range(4):
        r.box((L * 0.1, 0.0015, 0.0012), (L * 0.38, -0.009 + 0.006 * k, 0.0025), c, D_METAL)
    return _d(r, ["four pointed tines", "metal"], length=L)


@register("spoon")
def spoon(rng):
    r = Part("root")
    L = u(rng, 0.15, 0.19)
    c = pick(rng, METAL[:2])
    r.box((L * 0.3, 0.006, 0.002), (-L * 0.2, 0, 0.002), c, D_METAL)
    r.ellipsoid((L * 0.17, 0.018, 0.005), (L * 0.3, 0, 0.005), c, D_METAL)
    return _d(r, ["metal"], length=L)


@register("kitchen_knife")
def kitchen_knife(rng):
    r = Part("root")
    blade, handle, width = u(rng, 0.12, 0.2), u(rng, 0.09, 0.12), u(rng, 0.018, 0.04)
    hc = colour(rng, [DARK, WOOD[0], WOOD[2]])
    r.box((handle / 2, 0.011, 0.009), (-handle / 2, 0, 0.009), hc, D_WOOD)
    r.box(
        (blade / 2, width / 2, 0.0012),
        (blade / 2, -width / 2 + 0.011, 0.0092),
        METAL[0],
        D_METAL,
        name="blade",
    )
    r.box(
        (blade * 0.12, width * 0.3, 0.0012),
        (blade * 1.06, -width * 0.7 + 0.011, 0.0092),
        METAL[0],
        D_METAL,
        quat=axis_angle((0, 0, 1), -0.5),
    )
    return _d(r, ["long sharp steel blade", "pointed tip", f"{colour_name(hc)} handle"], blade=blade)


@register("cutting_board")
def cutting_board(rng):
    r = Part("root")
    hx, hy, t = u(rng, 0.15, 0.22), u(rng, 0.1, 0.15), u(rng, 0.008, 0.014)
    c = colour(rng, WOOD + [WHITE])
    r.box((hx, hy, t), (0, 0, t), c, D_WOOD)
    return Draft(r, {}, [Surface("top", (0, 0, 2 * t), (hx * 0.9, hy * 0.9))], [], [colour_name(c)])


@register("frying_pan")
def frying_pan(rng):
    r = Part("root")
    rad, hl = u(rng, 0.11, 0.14), u(rng, 0.16, 0.2)
    c = colour(rng, [DARK, METAL[2]])
    r.cyl(rad, 0.003, (0, 0, 0.003), c, D_METAL)
    r.ring(rad, 0.006, 0.045, 0.003, 14, c, D_METAL)
    r.box((hl / 2, 0.012, 0.008), (rad + hl / 2, 0, 0.03), DARK, 1100, name=HANDLE_GEOM)  # turned by world/states.py
    return Draft(
        r,
        {"radius": rad},
        [],
        [Cavity("inside", (0, 0, 0.025), (rad * 0.7, rad * 0.7, 0.018), "top")],
        ["long handle", "heavy metal"],
    )


# ----------------------------------------------------------------------------- food


def _apple(rng, rotten: bool):
    r = Part("root")
    rad = u(rng, 0.036, 0.044)
    c = (
        (0.45, 0.3, 0.12, 1)
        if rotten
        else colour(rng, [(0.8, 0.1, 0.1, 1), (0.5, 0.8, 0.2, 1), (0.9, 0.75, 0.2, 1)])
    )
    r.ellipsoid((rad, rad, rad * 0.9), (0, 0, rad * 0.9), c, 800)
    r.cyl(0.002, 0.008, (0, 0, rad * 1.8 + 0.006), (0.35, 0.22, 0.1, 1), 800)
    feats = [colour_name(c)]
    if rotten:
        for _ in range(4):
            a = u(rng, 0, 2 * math.pi)
            r.sphere(
                rad * 0.3,
                (rad * 0.8 * math.cos(a), rad * 0.8 * math.sin(a), rad * u(rng, 0.6, 1.2)),
                (0.2, 0.15, 0.05, 1),
                800,
                collide=False,
            )
        feats += ["brown soft rotten spots"]
    return _d(r, feats, radius=rad)


register("apple")(lambda rng: _apple(rng, False))
register("rotten_apple")(lambda rng: _apple(rng, True))


@register("banana")
def banana(rng):
    r = Part("root")
    rad, bend, n = u(rng, 0.016, 0.02), u(rng, 0.5, 0.9), 5
    c = colour(rng, [(0.95, 0.85, 0.2, 1), (0.75, 0.8, 0.2, 1)])
    pts = [
        (0.09 * math.sin(bend * (i / n - 0.5)) / bend * 1.9, 0.05 * (1 - math.cos(bend * (i / n - 0.5))), rad)
        for i in range(n + 1)
    ]
    for a, b in zip(pts, pts[1:], strict=False):
        r.segment(a, b, rad * 0.95, c, D_FOOD)
    return _d(r, ["yellow peel"], bend=bend)


def _bread(rng, moldy: bool):
    r = Part("root")
    hx, hy, hz = u(rng, 0.1, 0.14), u(rng, 0.05, 0.065), u(rng, 0.035, 0.05)
    c = (0.78, 0.55, 0.28, 1)
    r.box((hx, hy, hz), (0, 0, hz), c, 150)
    r.ellipsoid((hx * 0.98, hy * 0.98, hz * 0.6), (0, 0, 2 * hz), (0.65, 0.42, 0.2, 1), 150)
    feats = ["baked loaf"]
    if moldy:
        for _ in range(6):
            r.sphere(
                hy * u(rng, 0.2, 0.35),
                (u(rng, -hx, hx) * 0.8, u(rng, -hy, hy) * 0.6, 2 * hz + hz * 0.4),
                (0.35, 0.55, 0.35, 1),
                250,
                collide=False,
            )
        feats += ["green fuzzy mould spots", "spoiled"]
    return _d(r, feats, length=hx * 2)


register("bread_loaf")(lambda rng: _bread(rng, False))
register("moldy_bread")(lambda rng: _bread(rng, True))


@register("spoiled_milk_carton")
def spoiled_milk_carton(rng):
    r = Part("root")
    w, h = u(rng, 0.035, 0.05), u(rng, 0.15, 0.2)
    r.box((w, w, h / 2), (0, 0, h / 2), WHITE, 300)
    r.box(
        (w, w * 0.72, 0.004),
        (0, -w * 0.5, h + w * 0.45),
        (0.2, 0.45, 0.85, 1),
        300,
        quat=axis_angle((1, 0, 0), -0.78),
    )
    r.box(
        (w, w * 0.72, 0.004),
        (0, w * 0.5, h + w * 0.45),
        (0.2, 0.45, 0.85, 1),
        300,
        quat=axis_angle((1, 0, 0), 0.78),
    )
    r.box((w * 0.8, w * 0.4, h * 0.15), (0, -w - 0.0005, h * 0.55), (0.2, 0.45, 0.85, 1), 300, collide=False)
    return _d(r, ["gable-top carton", "milk past its date, sour"], height=h)


@register("raw_meat_tray")
def raw_meat_tray(rng):
    r = Part("root")
    hx, hy = u(rng, 0.1, 0.13), u(rng, 0.07, 0.09)
    r.box((hx, hy, 0.006), (0, 0, 0.006), WHITE, 300)
    r.ellipsoid((hx * 0.8, hy * 0.75, 0.02), (0, 0, 0.016), (0.8, 0.25, 0.3, 1), 1050)
    return _d(r, ["raw red meat on a foam tray", "wrapped in film"], length=hx * 2)


@register("cheese_block")
def cheese_block(rng):
    r = Part("root")
    hx, hy, hz = u(rng, 0.04, 0.07), u(rng, 0.025, 0.04), u(rng, 0.02, 0.035)
    r.box((hx, hy, hz), (0, 0, hz), (0.98, 0.8, 0.3, 1), 1100)
    return _d(r, ["yellow"], length=hx * 2)


@register("leftover_container")
def leftover_container(rng):
    r = Part("root")
    hx, hy, hz = u(rng, 0.06, 0.09), u(rng, 0.045, 0.07), u(rng, 0.025, 0.04)
    r.box((hx, hy, hz), (0, 0, hz), (0.85, 0.9, 0.95, 0.6), 500)
    r.box((hx * 1.03, hy * 1.03, 0.004), (0, 0, 2 * hz + 0.004), colour(rng, PLASTIC), 900)
    r.box((hx * 0.8, hy * 0.8, hz * 0.5), (0, 0, hz * 0.7), (0.7, 0.45, 0.2, 1), 1000, collide=False)
    return _d(r, ["plastic box with a lid", "leftover food inside"], length=hx * 2)


# ----------------------------------------------------------------------------- toys and small things


@register("toy_block")
def toy_block(rng):
    r = Part("root")
    s = u(rng, 0.015, 0.02)
    c = colour(rng, PLASTIC[:4] + WOOD[1:2])
    r.box((s, s, s), (0, 0, s), c, D_WOOD)
    return _d(r, [colour_name(c), "cube"], side=2 * s)


@register("toy_car")
def toy_car(rng):
    r = Part("root")
    L, w = u(rng, 0.035, 0.045), u(rng, 0.016, 0.02)
    c = colour(rng, PLASTIC)
    wr = 0.008
    r.box((L, w, 0.007), (0, 0, wr + 0.006), c, 1500)
    r.box((L * 0.5, w * 0.85, 0.007), (-L * 0.1, 0, wr + 0.019), (0.6, 0.8, 0.95, 1), 1500)
    for sx in (-1, 1):
        for sy in (-1, 1):
            r.cyl(wr, 0.003, (sx * L * 0.62, sy * (w + 0.002), wr), DARK, 1200, axis="y")
    return _d(r, [colour_name(c), "four small wheels"], length=2 * L)


@register("ball")
def ball(rng):
    r = Part("root")
    rad = u(rng, 0.06, 0.1)
    c = colour(rng, PLASTIC)
    r.sphere(rad, (0, 0, rad), c, 90)
    r.ellipsoid((rad * 1.005, rad * 0.15, rad * 1.005), (0, 0, rad), WHITE, 90, collide=False)
    return _d(r, [colour_name(c), "rolls easily"], radius=rad)


@register("marble")
def marble(rng):
    r = Part("root")
    rad = u(rng, 0.007, 0.012)
    c = colour(rng, [(0.2, 0.5, 0.9, 0.7), (0.9, 0.3, 0.3, 0.7), (0.3, 0.85, 0.5, 0.7)])
    r.sphere(rad, (0, 0, rad), c, D_GLASS)
    return _d(r, [colour_name(c), "glass sphere", "rolls"], radius=rad)


@register("coin")
def coin(rng):
    r = Part("root")
    rad = u(rng, 0.008, 0.014)
    c = colour(rng, [(0.8, 0.65, 0.3, 1), METAL[0], (0.72, 0.45, 0.25, 1)])
    r.cyl(rad, 0.001, (0, 0, 0.001), c, 8500)
    return _d(r, [colour_name(c), "metal disc"], radius=rad)


@register("button_battery")
def button_battery(rng):
    r = Part("root")
    rad = u(rng, 0.006, 0.0115)
    r.cyl(rad, 0.0016, (0, 0, 0.0016), METAL[0], 3500)
    r.cyl(rad * 0.8, 0.0004, (0, 0, 0.0034), METAL[1], 3500)
    return _d(r, ["silver coin cell, lithium", "causes internal burns if swallowed"], radius=rad)


@register("aa_battery")
def aa_battery(rng):
    r = Part("root")
    c = colour(rng, [(0.9, 0.6, 0.1, 1), (0.15, 0.15, 0.15, 1), (0.2, 0.5, 0.9, 1)])
    r.cyl(0.007, 0.0245, (0, 0, 0.007), c, 2600, axis="x")
    r.cyl(0.0025, 0.0008, (0.0253, 0, 0.007), METAL[0], 2600, axis="x")
    return _d(r, [colour_name(c), "cylindrical cell"], length=0.05)


@register("lego_brick")
def lego_brick(rng):
    r = Part("root")
    nx, ny = int(rng.integers(1, 5)), int(rng.integers(1, 3))
    p = 0.008
    c = colour(rng, PLASTIC)
    r.box((nx * p / 2, ny * p / 2, 0.0048), (0, 0, 0.0048), c, 700)
    for i in range(nx):
        for j in range(ny):
            r.cyl(0.0024, 0.0009, (-nx * p / 2 + p / 2 + i * p, -ny * p / 2 + p / 2 + j * p, 0.0105), c, 700)
    return _d(r, [colour_name(c), f"{nx}x{ny} studs", "painful to step on"], studs=nx * ny)


@register("balloon")
def balloon(rng):
    r = Part("root")
    L = u(rng, 0.06, 0.08)
    c = colour(rng, PLASTIC[:4])
    r.ellipsoid((L, L * 0.45, 0.003), (0, 0, 0.003), c, 900)
    r.cyl(0.006, L * 0.25, (-L - L * 0.2, 0, 0.006), c, 900, axis="x")
    return _d(r, [colour_name(c), "deflated rubber", "latex pieces are a choking hazard"], length=L)


# ----------------------------------------------------------------------------- cables


def _cable(rng, end: str):
    r = Part("root")
    rad = u(rng, 0.003, 0.005)
    n = int(rng.integers(8, 14))
    c = colour(rng, [DARK, WHITE, (0.2, 0.2, 0.25, 1), (0.9, 0.5, 0.1, 1)])
    pts = cable_path(rng, 1.0, n, rad)
    for a, b in zip(pts, pts[1:], strict=False):
        r.segment(a, b, rad, c, 1300)
    p0, p1 = pts[0], pts[-1]
    r.box((0.015, 0.012, 0.009), (p0[0] - 0.012, p0[1], 0.009), c, 1300)  # plug
    r.box((0.006, 0.002, 0.0015), (p0[0] - 0.032, p0[1] + 0.004, 0.009), METAL[0], D_METAL)
    r.box((0.006, 0.002, 0.0015), (p0[0] - 0.032, p0[1] - 0.004, 0.009), METAL[0], D_METAL)
    if end == "socket":
        r.box((0.09, 0.03, 0.02), (p1[0] + 0.08, p1[1], 0.02), c, 600)
        feats = ["long cord", "multi-socket block"]
    elif end == "charger":
        r.box((0.025, 0.025, 0.012), (p0[0] - 0.03, p0[1], 0.012), WHITE, 800)
        r.box((0.01, 0.006, 0.004), (p1[0] + 0.008, p1[1], rad), METAL[1], 1500)
        feats = ["thin charging cable", "charger brick"]
    else:
        feats = ["loose cord lying across the floor"]
    return _d(r, feats + [colour_name(c)], links=n)


register("power_cable")(lambda rng: _cable(rng, "plug"))
register("extension_cord")(lambda rng: _cable(rng, "socket"))
register("phone_charger")(lambda rng: _cable(rng, "charger"))


# ----------------------------------------------------------------------------- reading, clothing, textiles


@register("book")
def book(rng):
    r = Part("root")
    hx, hy, hz = u(rng, 0.075, 0.11), u(rng, 0.1, 0.14), u(rng, 0.01, 0.025)
    c = colour(rng, FABRIC + PLASTIC[:3])
    r.box((hx, hy, hz), (0, 0, hz), c, 700)
    r.box((hx * 0.98, hy * 0.96, hz * 0.85), (0.003, 0, hz), (0.95, 0.93, 0.86, 1), 700, collide=False)
    return Draft(
        r, {}, [Surface("cover", (0, 0, 2 * hz), (hx * 0.9, hy * 0.9))], [], [colour_name(c), "hard cover"]
    )


@register("magazine")
def magazine(rng):
    r = Part("root")
    hx, hy = u(rng, 0.1, 0.11), u(rng, 0.135, 0.15)
    c = colour(rng, PLASTIC)
    r.box((hx, hy, 0.002), (0, 0, 0.002), c, 800)
    return _d(r, [colour_name(c), "glossy, slippery on the floor"], pages=int(rng.integers(40, 120)))


def _shoe(rng, slipper: bool):
    r = Part("root")
    L, w = u(rng, 0.12, 0.14), u(rng, 0.04, 0.05)
    c = colour(rng, FABRIC + [DARK, WHITE])
    r.box((L, w, 0.01), (0, 0, 0.01), DARK if not slipper else c, 600)
    if slipper:
        r.ellipsoid((L * 0.4, w * 1.0, 0.03), (L * 0.45, 0, 0.02), c, 200)
    else:
        r.ellipsoid((L * 0.95, w * 0.95, 0.045), (0, 0, 0.055), c, 300)  # above the sole, so it rests flat
        r.box((L * 0.25, w * 0.9, 0.035), (-L * 0.7, 0, 0.05), c, 300)
    return _d(r, [colour_name(c)], length=2 * L)


register("shoe")(lambda rng: _shoe(rng, False))
register("slipper")(lambda rng: _shoe(rng, True))


@register("towel")
def towel(rng):
    r = Part("root")
    hx, hy, hz = u(rng, 0.15, 0.22), u(rng, 0.1, 0.15), u(rng, 0.01, 0.025)
    c = colour(rng, FABRIC + [WHITE])
    r.box((hx, hy, hz), (0, 0, hz), c, 200)
    return _d(r, [colour_name(c), "folded soft cloth"], length=2 * hx)


@register("rug")
def rug(rng):
    r = Part("root")
    hx, hy = u(rng, 0.4, 0.6), u(rng, 0.25, 0.4)
    c = colour(rng, FABRIC)
    r.box((hx, hy, 0.004), (0, 0, 0.004), c, 300)
    r.box((hx * 0.8, hy * 0.7, 0.0045), (0, 0, 0.004), colour(rng, FABRIC), 300, collide=False)
    r.box(
        (hx * 0.08, hy * 0.6, 0.004), (hx * 0.7, 0, 0.011), c, 300, quat=axis_angle((0, 1, 0), -0.2)
    )  # curled corner
    return _d(r, [colour_name(c), "curled edge", "loose on the floor"], length=2 * hx)


@register("backpack")
def backpack(rng):
    r = Part("root")
    hx, hy, hz = u(rng, 0.13, 0.16), u(rng, 0.06, 0.09), u(rng, 0.17, 0.21)
    c = colour(rng, FABRIC + PLASTIC[:3])
    r.box((hx, hy, hz * 0.8), (0, 0, hz * 0.8), c, 80)
    r.ellipsoid((hx, hy, hz * 0.35), (0, 0, hz * 1.55), c, 80)
    r.box((hx * 0.7, hy * 0.4, hz * 0.35), (0, -hy * 1.35, hz * 0.45), c, 80)
    for sx in (-1, 1):
        r.box((0.02, 0.01, hz * 0.7), (sx * hx * 0.5, hy + 0.01, hz * 1.0), DARK, 300)
    return _d(r, [colour_name(c), "straps"], height=2 * hz)


# ----------------------------------------------------------------------------- heat and fire

SNUFFER_TRAVEL = 0.025  # m a candle's bell snuffer rises off the wick while lit (clear of the flame at 70 %)


@register("candle")
def candle(rng):
    r = Part("root")
    rad, h = u(rng, 0.02, 0.035), u(rng, 0.06, 0.16)
    c = colour(rng, [WHITE, (0.95, 0.9, 0.75, 1), (0.8, 0.2, 0.2, 1)])
    r.cyl(rad, h / 2, (0, 0, h / 2), c, 900)
    r.cyl(0.001, 0.004, (0, 0, h + 0.004), DARK, 900)
    # The flame shows only while the candle is lit, i.e. its bell snuffer is raised (label "switch":
    # lit = on, pressed down over the wick = out). Pressed straight down, a light candle cannot tip.
    glow(r, "snuffer", "ellipsoid", (0.004, 0.004, 0.007), (0, 0, h + 0.01))
    # down, the bell fills the lit candle's old box (flame top h + 0.025), so the candle keeps its size
    cap = r.child("snuffer", (0, 0, h))
    cap.slide("snuffer_press", (0, 0, 1), (0, SNUFFER_TRAVEL), SWITCH, 0.0, hold=True)
    cap.cyl(rad * 0.9, 0.0125, (0, 0, 0.0125), (0.75, 0.6, 0.3, 1), 1200)
    cap.cyl(0.0015, 0.02, (0, rad * 0.8, -0.02), (0.75, 0.6, 0.3, 1), 1, collide=False)  # its guide pin
    return _d(r, ["bell snuffer", colour_name(c)], height=h)


@register("iron")
def iron(rng):
    r = Part("root")
    L, w = u(rng, 0.12, 0.14), u(rng, 0.05, 0.06)
    c = colour(rng, PLASTIC)
    r.box((L, w, 0.008), (0, 0, 0.008), METAL[0], D_METAL)
    r.box((L * 0.35, w * 0.5, 0.008), (L, 0, 0.008), METAL[0], D_METAL, quat=axis_angle((0, 0, 1), 0.0))
    r.ellipsoid((L * 0.95, w * 0.9, 0.035), (0, 0, 0.03), c, 300)
    r.segment((-L * 0.6, 0, 0.07), (L * 0.4, 0, 0.08), 0.012, c, 300)
    r.segment((-L * 0.6, 0, 0.07), (-L * 0.75, 0, 0.045), 0.012, c, 300)
    # the power switch on the body's nose, clear of the handle by more than the cup's radius, and
    # standing above the body all round the cup even when pressed down (off)
    xs = L * 0.75
    top = 0.03 + 0.035 * float(np.sqrt(max(0.0, 1.0 - ((xs - 0.02) / (L * 0.95)) ** 2)))
    push_switch(r, "switch", (xs, 0, top - 0.001), (0.008, 0.008, 0.004), DARK)
    glow(r, SWITCH, "sphere", (0.004,), (L * 0.25, 0, 0.095))  # the heating light
    return _d(r, [colour_name(c), "hot steel soleplate", "power switch", "power cord"], length=2 * L)


@register("hair_dryer")
def hair_dryer(rng):
    r = Part("root")
    rb, lb = u(rng, 0.035, 0.045), u(rng, 0.08, 0.11)
    c = colour(rng, PLASTIC)
    r.cyl(rb, lb, (0, 0, rb), c, 300, axis="x")
    r.cyl(rb * 0.7, 0.01, (lb + 0.01, 0, rb), DARK, 300, axis="x")
    r.box((0.02, 0.05, rb * 0.55), (-lb * 0.3, -rb - 0.045, rb * 0.55), c, 300)
    push_switch(r, "switch", (-lb * 0.3, -rb - 0.06, rb * 1.1 + 0.002), (0.008, 0.012, 0.004), (0.85, 0.1, 0.1, 1))
    return _d(r, [colour_name(c), "handle", "on/off switch", "power cord"], length=2 * lb)


@register("matches")
def matches(rng):
    r = Part("root")
    hx, hy, hz = u(rng, 0.024, 0.028), u(rng, 0.017, 0.02), u(rng, 0.007, 0.009)
    c = colour(rng, PLASTIC[:4])
    r.box((hx, hy, hz), (0, 0, hz), c, 500)
    r.box((hx * 0.95, 0.0008, hz * 0.8), (0, -hy, hz), (0.35, 0.2, 0.1, 1), 500, collide=False)
    return _d(r, ["small box of matches", "strike strip"], length=2 * hx)


# ----------------------------------------------------------------------------- litter, decor, garden


@register("plastic_bag")
def plastic_bag(rng):
    r = Part("root")
    c = colour(rng, [WHITE, (0.9, 0.9, 0.8, 0.9), (0.3, 0.5, 0.8, 0.9)])
    for _ in range(4):  # flat overlapping folds: a crumpled bag lying flat, stable on the floor
        hz = u(rng, 0.003, 0.008)
        r.box(
            (u(rng, 0.06, 0.12), u(rng, 0.05, 0.09), hz),
            (u(rng, -0.05, 0.05), u(rng, -0.04, 0.04), hz),
            c,
            20,
            quat=axis_angle((0, 0, 1), u(rng, 0, math.pi)),
        )
    return _d(r, ["thin crumpled plastic"], pieces=4)


@register("vase")
def vase(rng):
    r = Part("root")
    rad, h = u(rng, 0.05, 0.08), u(rng, 0.2, 0.3)
    c = colour(rng, CERAMIC + [(0.2, 0.35, 0.6, 1)])
    r.cyl(rad * 0.6, 0.01, (0, 0, 0.01), c, D_CERAMIC)
    r.ellipsoid((rad, rad, h * 0.35), (0, 0, h * 0.38), c, 600)
    r.cyl(rad * 0.4, h * 0.15, (0, 0, h * 0.8), c, 600)
    r.cyl(rad * 0.5, 0.008, (0, 0, h * 0.95), c, 600)
    return _d(r, [colour_name(c), "ceramic"], height=h)


@register("plant_pot")
def plant_pot(rng):
    r = Part("root")
    rad, h = u(rng, 0.07, 0.12), u(rng, 0.1, 0.16)
    c = colour(rng, [(0.72, 0.38, 0.22, 1), WHITE, DARK])
    r.cyl(rad, h / 2, (0, 0, h / 2), c, 1400)
    r.cyl(rad * 1.08, 0.01, (0, 0, h - 0.01), c, 1400)
    r.cyl(0.006, h * 0.4, (0, 0, h + h * 0.4), (0.3, 0.5, 0.2, 1), 600)
    r.ellipsoid((rad * 1.2, rad * 1.2, h * 0.6), (0, 0, h * 1.6), (0.2, 0.55, 0.2, 1), 100)
    return _d(r, ["potted green plant", "heavy soil"], height=h)


@register("watering_can")
def watering_can(rng):
    r = Part("root")
    rad, h = u(rng, 0.07, 0.09), u(rng, 0.14, 0.2)
    c = colour(rng, PLASTIC + METAL[:1])
    r.cyl(rad, h / 2, (0, 0, h / 2), c, 300)
    r.segment((rad * 0.8, 0, h * 0.3), (rad + 0.15, 0, h * 1.1), 0.012, c, 300)
    r.segment((-rad * 0.9, 0, h * 0.95), (-rad * 0.9, 0, h * 0.35), 0.01, c, 300)
    r.segment((-rad * 0.9, 0, h * 0.95), (rad * 0.3, 0, h * 1.25), 0.01, c, 300)
    r.segment((rad * 0.3, 0, h * 1.25), (rad * 0.3, 0, h), 0.01, c, 300)
    return _d(r, [colour_name(c), "long spout"], height=h)


@register("garden_shears")
def garden_shears(rng):
    r = Part("root")
    bl, hl, a = u(rng, 0.08, 0.11), u(rng, 0.14, 0.18), u(rng, 0.1, 0.3)
    hc = colour(rng, PLASTIC[:3] + WOOD[:1])
    for s in (-1, 1):
        q = axis_angle((0, 0, 1), s * a)
        ca, sa = math.cos(s * a), math.sin(s * a)
        r.box(
            (bl / 2, 0.012, 0.003),
            (ca * bl / 2, sa * bl / 2, 0.003 + (s + 1) * 0.003),
            METAL[0],
            D_METAL,
            quat=q,
        )
        r.box((hl / 2, 0.011, 0.009), (-ca * hl / 2, -sa * hl / 2, 0.009), hc, D_WOOD, quat=q)
    return _d(r, ["two sharp blades", "long handles"], opening=a)


def _handle_tool(rng, name):
    r = Part("root")
    if name == "screwdriver":
        hl, sl = u(rng, 0.08, 0.11), u(rng, 0.07, 0.13)
        c = colour(rng, PLASTIC[:4])
        r.box((hl / 2, 0.013, 0.013), (-hl / 2, 0, 0.013), c, 900)
        r.cyl(0.0035, sl / 2, (sl / 2, 0, 0.013), METAL[0], D_METAL, axis="x")
        r.box((0.006, 0.004, 0.0008), (sl + 0.004, 0, 0.013), METAL[0], D_METAL)
        return _d(r, [colour_name(c), "steel shaft", "flat pointed tip"], shaft=sl)
    if name == "hammer":
        hl = u(rng, 0.22, 0.28)
        c = colour(rng, WOOD + [DARK])
        r.box((hl / 2, 0.013, 0.01), (0, 0, 0.016), c, D_WOOD)
        r.box((0.018, 0.055, 0.016), (hl / 2 + 0.01, 0, 0.016), METAL[2], D_METAL)
        return _d(r, ["steel head", f"{colour_name(c)} handle"], handle=hl)
    if name == "razor":
        hl = u(rng, 0.09, 0.12)
        c = colour(rng, PLASTIC)
        r.box((hl / 2, 0.007, 0.005), (-hl / 2, 0, 0.005), c, 1000)
        r.box((0.009, 0.022, 0.005), (0.008, 0, 0.005), c, 1000)
        r.box((0.003, 0.02, 0.0008), (0.012, 0, 0.0105), METAL[0], D_METAL, name="blade")
        return _d(r, [colour_name(c), "exposed razor blades"], handle=hl)
    if name == "nail":
        L = u(rng, 0.03, 0.07)
        r.box((L / 2, 0.0012, 0.0012), (0, 0, 0.0035), METAL[1], D_METAL)
        r.box((0.0008, 0.0035, 0.0035), (-L / 2, 0, 0.0035), METAL[1], D_METAL)
        return _d(r, ["steel", "sharp point"], length=L)
    L = u(rng, 0.03, 0.05)  # needle
    # Seen 1 mm thick, but it collides as a 3 mm capsule: a 0.5 mm radius slipped through an 8 mm
    # box bottom in simulation.
    r.capsule(0.0005, L / 2, (0, 0, 0.0015), METAL[0], D_METAL, axis="x", collide=False)
    r.capsule(0.0015, L / 2, (0, 0, 0.0015), (0.75, 0.75, 0.78, 0.0), D_METAL, axis="x")
    return _d(r, ["thin steel", "very sharp point"], length=L)


for _n in ("screwdriver", "hammer", "razor", "nail", "needle"):
    register(_n)(lambda rng, _n=_n: _handle_tool(rng, _n))


@register("tissue_box")
def tissue_box(rng):
    r = Part("root")
    hx, hy, hz = u(rng, 0.1, 0.12), u(rng, 0.055, 0.065), u(rng, 0.04, 0.06)
    c = colour(rng, PLASTIC + CERAMIC)
    r.box((hx, hy, hz), (0, 0, hz), c, 100)
    r.ellipsoid((0.03, 0.02, 0.02), (0, 0, 2 * hz + 0.008), WHITE, 50, collide=False)
    return _d(r, [colour_name(c)], length=2 * hx)


@register("wrapper")
def wrapper(rng):
    r = Part("root")
    c = colour(rng, PLASTIC)
    hx, hy = u(rng, 0.05, 0.07), u(rng, 0.025, 0.035)
    r.box((hx, hy, 0.002), (0, 0, 0.002), c, 500)
    r.box((hx * 0.3, hy * 0.9, 0.002), (hx * 0.9, 0, 0.005), c, 500, quat=axis_angle((0, 1, 0), -0.3))
    return _d(r, [colour_name(c), "empty crumpled snack wrapper"], length=2 * hx)


@register("paper_ball")
def paper_ball(rng):
    r = Part("root")
    rad = u(rng, 0.025, 0.035)
    c = colour(rng, [WHITE, (0.95, 0.93, 0.8, 1)])
    r.ellipsoid((rad, rad * 0.95, rad * 0.8), (0, 0, rad * 0.8), c, 80)  # flattened so it lies still
    for _ in range(5):
        d = rng.normal(size=3)
        d = d / np.linalg.norm(d) * rad * 0.6
        r.sphere(rad * 0.45, (d[0], d[1], rad * 0.8 + d[2] * 0.5), c, 1e-3, collide=False)
    return _d(r, ["crumpled paper"], radius=rad)


@register("soda_can")
def soda_can(rng):
    r = Part("root")
    c = colour(rng, PLASTIC)
    r.cyl(0.033, 0.06, (0, 0, 0.06), c, 60)
    r.cyl(0.027, 0.002, (0, 0, 0.122), METAL[0], 60)
    return _d(r, [colour_name(c), "empty aluminium can"], height=0.124)


@register("dumbbell")
def dumbbell(rng):
    r = Part("root")
    bar, rad = u(rng, 0.1, 0.14), u(rng, 0.04, 0.06)
    c = colour(rng, [DARK, METAL[1], (0.7, 0.2, 0.3, 1)])
    r.cyl(0.014, bar / 2 + 0.03, (0, 0, rad), METAL[1], D_METAL, axis="x")
    for s in (-1, 1):
        r.box((0.025, rad * 0.87, rad * 0.87), (s * (bar / 2 + 0.025), 0, rad * 0.87), c, D_METAL)
    return _d(r, [colour_name(c), "iron weights"], bar=bar)


# ----------------------------------------------------------------------------- storage and furniture


@register("storage_box")
def storage_box(rng):
    r = Part("root")
    hx, hy, hz, t = u(rng, 0.18, 0.28), u(rng, 0.13, 0.2), u(rng, 0.1, 0.16), 0.008
    c = colour(rng, PLASTIC + WOOD[:2])
    open_box(r, hx, hy, hz, t, c, 900)
    lid = r.child("lid", (0, hy, 2 * hz + 0.002))
    lid.hinge("lid_hinge", (1, 0, 0), (-1.9, 0), LID, 0.0)
    # a 6 mm plastic lid: the 12 mm one weighed 1.5 kg and its holding friction tipped the box
    lid.box((hx + 0.004, hy + 0.002, 0.003), (0, -hy, 0.003), c, 900)
    return Draft(
        r,
        {"size_x": hx},
        [Surface("lid_top", (0, 0, 2 * hz + 0.014), (hx * 0.9, hy * 0.9))],
        [Cavity("inside", (0, 0, hz + t / 2), (hx - t * 1.5, hy - t * 1.5, hz - t), "top", "lid_hinge")],
        [colour_name(c), "hinged lid"],
    )


@register("basket")
def basket(rng):
    r = Part("root")
    rad, h = u(rng, 0.12, 0.18), u(rng, 0.08, 0.14)
    c = colour(rng, WOOD)
    r.cyl(rad, 0.004, (0, 0, 0.004), c, D_WOOD)
    r.ring(rad, 0.008, h, 0.006, 14, c, D_WOOD, ry=rad * 0.75)
    return Draft(
        r,
        {"radius": rad},
        [],
        [Cavity("inside", (0, 0, h / 2), (rad * 0.7, rad * 0.5, h / 2 - 0.01), "top")],
        ["woven", "open top"],
    )


@register("shelf")
def shelf(rng):
    r = Part("root")
    hx, hy, h = u(rng, 0.3, 0.45), u(rng, 0.12, 0.18), u(rng, 0.5, 1.1)
    n = int(rng.integers(2, 5))
    t = 0.018
    c = colour(rng, WOOD + [WHITE])
    for sx in (-1, 1):
        r.box((t / 2, hy, h / 2), (sx * (hx - t / 2), 0, h / 2), c, D_WOOD)
    r.box((hx, 0.004, h / 2), (0, hy - 0.004, h / 2), c, D_WOOD)
    surfaces = []
    for i in range(n + 1):
        z = 0.04 + (h - 0.04 - t) * i / n
        r.box((hx - t, hy, t / 2), (0, 0, z + t / 2), c, D_WOOD)
        surfaces.append(Surface(f"board_{i}", (0, 0, z + t), (hx - t - 0.01, hy - 0.01)))
    return Draft(r, {"boards": n + 1}, surfaces, [], [f"{n + 1} shelf boards", colour_name(c)])


@register("counter")
def counter(rng, size=None):
    """A worktop on a cabinet. Asked for a ``size`` (its largest dimension), it is built that long and
    keeps a counter's height and depth: a kitchen counter is 0.86-0.92 m high however long it is."""
    r = Part("root")
    hx, hy, h = u(rng, 0.5, 1.0), u(rng, 0.28, 0.32), u(rng, 0.86, 0.92)
    if size is not None:
        hx = max(hy, h / 2, size / 2 - 0.01)  # the top overhangs the cabinet by 0.01 m
    body = colour(rng, WOOD + [WHITE, (0.3, 0.35, 0.45, 1)])
    top = colour(rng, [(0.85, 0.84, 0.8, 1), (0.2, 0.2, 0.22, 1), WOOD[3]])
    r.box((hx, hy - 0.02, h / 2 - 0.02), (0, 0.02, h / 2 - 0.02), body, 300)
    r.box((hx + 0.01, hy + 0.01, 0.02), (0, 0, h - 0.02), top, 2400)
    n = max(1, int(hx / 0.3))
    for i in range(n):  # front panels and handles (decoration)
        x = -hx + hx / n * (2 * i + 1)
        r.box(
            (hx / n - 0.006, 0.003, h / 2 - 0.08),
            (x, -hy + 0.018, h / 2 - 0.02),
            (body[0] * 0.9, body[1] * 0.9, body[2] * 0.9, 1),
            300,
            collide=False,
        )
        r.box((0.04, 0.006, 0.006), (x, -hy + 0.01, h - 0.12), METAL[0], D_METAL, collide=False)
    return Draft(
        r,
        {"length": 2 * hx},
        [Surface("top", (0, 0, h), (hx - 0.02, hy - 0.02))],
        [],
        ["worktop", colour_name(top)],
    )


@register("medicine_cabinet")
def medicine_cabinet(rng):
    r = Part("root")
    hx, hy, hz, t = u(rng, 0.16, 0.25), u(rng, 0.06, 0.09), u(rng, 0.2, 0.28), 0.012
    c = colour(rng, [WHITE, WOOD[1], METAL[0]])
    open_box(r, hx, hy, hz, t, c, D_WOOD, top=True, front=False)
    r.box((hx - t, hy - t, t / 2), (0, 0, hz), c, D_WOOD)  # shelf
    door = r.child("door", (-hx, -hy - 0.003, hz))
    door.hinge("door_hinge", (0, 0, 1), (-2.0, 0), DOOR, 0.0)
    door.box((hx - 0.002, 0.006, hz - 0.002), (hx, -0.003, 0), c, D_WOOD)
    door.box((hx * 0.8, 0.001, hz * 0.8), (hx, -0.0095, 0), (0.8, 0.88, 0.92, 1), D_GLASS, collide=False)
    door.box((0.006, 0.01, 0.03), (2 * hx - 0.03, -0.018, 0), METAL[0], D_METAL)
    cav = [
        Cavity(
            "lower", (0, 0, hz / 2 + t / 2), (hx - t * 1.5, hy - t * 1.5, hz / 2 - t), "front", "door_hinge"
        ),
        Cavity("upper", (0, 0, hz * 1.5), (hx - t * 1.5, hy - t * 1.5, hz / 2 - t), "front", "door_hinge"),
    ]
    surfs = [
        Surface("top", (0, 0, 2 * hz), (hx - 0.01, hy - 0.01)),
        Surface("shelf", (0, 0, hz + t / 2), (hx - t * 1.5, hy - t * 1.5)),
    ]
    return Draft(r, {}, surfs, cav, ["mirrored door", "shelf inside"])
