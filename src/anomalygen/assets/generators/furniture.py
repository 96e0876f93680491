"""Large targets: cabinets, appliances with doors, doors and windows, tables, chairs, toilet, bins, cart.

Nominal sizes are realistic so the default (unscaled) variant is already plausible; seeds vary grid
layout, part counts, proportions and materials.
"""

from __future__ import annotations

import math

from anomalygen.assets.generators.common import (
    APPLIANCE,
    BLACK_GLASS,
    D_HOLLOW,
    D_METAL,
    D_WOOD,
    DARK,
    FABRIC,
    GLASS,
    METAL,
    PLASTIC,
    WHITE,
    WOOD,
    colour,
    colour_name,
    open_box,
    pick,
    u,
)
from anomalygen.assets.generators.parts_lib import drawer, drop_door, knob, side_door, top_lid
from anomalygen.assets.model import Cavity, Draft, Surface
from anomalygen.assets.parts import Part
from anomalygen.assets.registry import register
from anomalygen.schema import DIAL, DOOR, DRAWER, LID, SASH


def _cells(r: Part, hx, hy, z0, z1, cols: int, rows: int, t: float, rgba, density, rng, prefix=""):
    """Fill the front of a shell (x in ±hx, z0..z1) with a grid of doors and drawers.

    Returns (cavities, features). Rows are separated by boards; a row is all drawers or all doors.
    """
    cavities, n_doors, n_drawers = [], 0, 0
    row_h = (z1 - z0) / rows
    for i in range(rows):
        za, zb = z0 + i * row_h, z0 + (i + 1) * row_h
        if i > 0:
            r.box((hx - t, hy - t, t / 2), (0, 0, za), rgba, density)
        kind = DRAWER if (row_h < 0.35 and rng.random() < 0.7) or rng.random() < 0.25 else DOOR
        for j in range(cols):
            xa, xb = -hx + 2 * hx * j / cols, -hx + 2 * hx * (j + 1) / cols
            name = f"{prefix}{kind}_{i}_{j}"
            if kind == DRAWER:
                _, cav = drawer(
                    r,
                    name,
                    xa + 0.003,
                    xb - 0.003,
                    za + 0.003,
                    zb - 0.003,
                    -hy,
                    2 * hy - 2 * t,
                    rgba,
                    density,
                )
                cavities.append(cav)
                n_drawers += 1
            else:
                left = (j % 2 == 0) if cols > 1 else bool(rng.random() < 0.5)
                side_door(r, name, xa + 0.003, xb - 0.003, za + 0.003, zb - 0.003, -hy, left, rgba, density)
                cavities.append(
                    Cavity(
                        f"{name}_space",
                        ((xa + xb) / 2, 0, (za + zb) / 2 + t / 2),
                        ((xb - xa) / 2 - t, hy - 1.5 * t, row_h / 2 - t),
                        "front",
                        f"{name}_hinge",
                    )
                )
                n_doors += 1
    feats = []
    if n_doors:
        feats.append(f"{n_doors} door{'s' * (n_doors > 1)}")
    if n_drawers:
        feats.append(f"{n_drawers} drawer{'s' * (n_drawers > 1)}")
    return cavities, feats


@register("StorageFurniture")
def storage_furniture(rng):
    r = Part("root")
    t = 0.018
    cols, rows = int(rng.integers(1, 4)), int(rng.integers(1, 4))
    while cols * rows > 6:
        rows -= 1
    hx = u(rng, 0.2, 0.3) * cols
    hy = u(rng, 0.2, 0.28)
    h = u(rng, 0.3, 0.45) * rows + 0.08
    c = colour(rng, WOOD + [WHITE, (0.35, 0.4, 0.5, 1)])
    open_box(r, hx, hy, h / 2, t, c, D_WOOD, top=True, front=False)
    r.box(
        (hx - 0.01, hy - 0.01, 0.04), (0, 0.005, 0.04), (c[0] * 0.7, c[1] * 0.7, c[2] * 0.7, 1), D_WOOD
    )  # plinth
    cavities, feats = _cells(r, hx - t, hy, 0.08 + 0.004, h - t, cols, rows, t, c, D_WOOD, rng)
    return Draft(
        r,
        {"cols": cols, "rows": rows},
        [Surface("top", (0, 0, h), (hx - 0.01, hy - 0.01))],
        cavities,
        feats + [colour_name(c), "cabinet"],
    )


@register("Refrigerator")
def refrigerator(rng):
    r = Part("root")
    hx, hy, h, t = u(rng, 0.3, 0.45), u(rng, 0.3, 0.36), u(rng, 1.5, 1.85), 0.04
    c = colour(rng, APPLIANCE)
    open_box(r, hx, hy, h / 2, t, c, D_HOLLOW, top=True, front=False)
    freezer_h = u(rng, 0.35, 0.5)
    layout = pick(rng, ["bottom_drawer", "top_door"])
    two = hx > 0.38 and rng.random() < 0.6
    surfaces, cavities = [], []
    if layout == "bottom_drawer":
        r.box((hx - t, hy - t, t / 2), (0, 0, freezer_h), c, D_HOLLOW)
        _, cav = drawer(
            r, "freezer", -hx + 0.004, hx - 0.004, 0.004, freezer_h - 0.004, -hy, 2 * hy - 2 * t, c, D_HOLLOW
        )
        cavities.append(Cavity("freezer", cav.center, cav.half_extents, "top", cav.joint))
        z_main0, z_main1 = freezer_h, h
    else:
        r.box((hx - t, hy - t, t / 2), (0, 0, h - freezer_h), c, D_HOLLOW)
        side_door(
            r,
            "freezer_door",
            -hx + 0.004,
            hx - 0.004,
            h - freezer_h + 0.004,
            h - 0.004,
            -hy,
            False,
            c,
            D_HOLLOW,
            thick=0.05,
        )
        cavities.append(
            Cavity(
                "freezer",
                (0, 0, h - freezer_h / 2),
                (hx - 1.5 * t, hy - 1.5 * t, freezer_h / 2 - t),
                "front",
                "freezer_door_hinge",
            )
        )
        z_main0, z_main1 = 0.0, h - freezer_h
    n_shelves = int(rng.integers(2, 4))
    for k in range(n_shelves):
        z = z_main0 + (z_main1 - z_main0) * (k + 1) / (n_shelves + 1)
        r.box((hx - t, hy - t, 0.005), (0, 0.01, z), GLASS, 2500)
        surfaces.append(Surface(f"shelf_{k}", (0, 0.01, z + 0.005), (hx - t - 0.01, hy - t - 0.02)))
    main_joint = "door_hinge"
    if two:
        side_door(
            r,
            "door_left",
            -hx + 0.004,
            -0.003,
            z_main0 + 0.004,
            z_main1 - 0.004,
            -hy,
            True,
            c,
            D_HOLLOW,
            thick=0.05,
        )
        side_door(
            r,
            "door_right",
            0.003,
            hx - 0.004,
            z_main0 + 0.004,
            z_main1 - 0.004,
            -hy,
            False,
            c,
            D_HOLLOW,
            thick=0.05,
        )
        main_joint = "door_left_hinge"
    else:
        side_door(
            r,
            "door",
            -hx + 0.004,
            hx - 0.004,
            z_main0 + 0.004,
            z_main1 - 0.004,
            -hy,
            bool(rng.random() < 0.5),
            c,
            D_HOLLOW,
            thick=0.05,
        )
    cavities.insert(
        0,
        Cavity(
            "fridge",
            (0, 0, (z_main0 + z_main1) / 2),
            (hx - 1.5 * t, hy - 1.5 * t, (z_main1 - z_main0) / 2 - t),
            "front",
            main_joint,
        ),
    )
    surfaces.append(Surface("top", (0, 0, h), (hx - 0.01, hy - 0.01)))
    feats = [
        colour_name(c),
        "two doors" if two else "one door",
        f"freezer {'drawer at the bottom' if layout == 'bottom_drawer' else 'door on top'}",
        "keeps food cold",
    ]
    return Draft(r, {"layout": layout, "two_doors": two}, surfaces, cavities, feats)


def _appliance_shell(r, hx, hy, h, t, c):
    open_box(r, hx, hy, h / 2, t, c, D_HOLLOW, top=True, front=False)


@register("Oven")
def oven(rng):
    r = Part("root")
    hx, hy, h, t = u(rng, 0.28, 0.38), u(rng, 0.27, 0.32), u(rng, 0.75, 0.9), 0.03
    c = colour(rng, APPLIANCE)
    _appliance_shell(r, hx, hy, h, t, c)
    panel = 0.1
    r.box((hx, 0.02, panel / 2), (0, -hy - 0.02, h - panel / 2), c, D_HOLLOW)  # control panel
    r.box((hx - t, hy - t, 0.005), (0, 0, h * 0.35), METAL[1], D_METAL)  # rack
    drop_door(
        r, "door", -hx + 0.004, hx - 0.004, 0.06, h - panel - 0.004, -hy, c, D_HOLLOW, window=BLACK_GLASS
    )
    n = int(rng.integers(2, 6))
    for k in range(n):
        x = -hx * 0.8 + 1.6 * hx * (k + 0.5) / n
        knob(r, f"knob_{k}", (x, -hy - 0.04, h - panel / 2), 0.018, DARK)
    surfaces = [
        Surface("cooktop", (0, 0, h), (hx - 0.01, hy - 0.01)),
        Surface("rack", (0, 0, h * 0.35 + 0.005), (hx - t - 0.01, hy - t - 0.01)),
    ]
    cav = [
        Cavity(
            "oven",
            (0, 0, (0.06 + h - panel) / 2),
            (hx - 1.5 * t, hy - 1.5 * t, (h - panel - 0.06) / 2 - t),
            "front",
            "door_hinge",
        )
    ]
    for k in range(4):  # burners on the cooktop
        r.cyl(
            0.06,
            0.003,
            ((-1) ** k * hx * 0.45, (-1) ** (k // 2) * hy * 0.45, h + 0.003),
            DARK,
            D_METAL,
            collide=False,
        )
    return Draft(
        r,
        {"knobs": n},
        surfaces,
        cav,
        [colour_name(c), "drop-down door with a window", f"{n} control knobs", "hot inside when on"],
    )


@register("Dishwasher")
def dishwasher(rng):
    r = Part("root")
    hx, hy, h, t = u(rng, 0.29, 0.31), u(rng, 0.28, 0.31), u(rng, 0.8, 0.86), 0.03
    c = colour(rng, APPLIANCE)
    _appliance_shell(r, hx, hy, h, t, c)
    drop_door(
        r, "door", -hx + 0.004, hx - 0.004, 0.08, h - 0.004, -hy, c, D_HOLLOW, handle=rng.random() < 0.7
    )
    rack = r.child("rack", (0, 0, h * 0.25))
    depth = 2 * hy - 2 * t - 0.04
    rack.slide("rack_slide", (0, -1, 0), (0, depth * 0.8), "rack", 0.0)
    rw = hx - t - 0.02
    for s in (-1, 1):
        rack.box((0.004, depth / 2, 0.05), (s * rw, 0, 0.05), METAL[0], D_METAL)
        rack.box((rw, 0.004, 0.05), (0, s * depth / 2, 0.05), METAL[0], D_METAL)
    for k in range(5):
        rack.box((rw, 0.003, 0.003), (0, -depth / 2 + depth * (k + 0.5) / 5, 0.003), METAL[0], D_METAL)
    cav = [
        Cavity(
            "tub", (0, 0, h / 2 + 0.04), (hx - 1.5 * t, hy - 1.5 * t, h / 2 - 0.04 - t), "front", "door_hinge"
        ),
        Cavity("rack", (0, 0, h * 0.25 + 0.06), (rw - 0.01, depth / 2 - 0.01, 0.05), "top", "rack_slide"),
    ]
    return Draft(
        r,
        {},
        [Surface("top", (0, 0, h), (hx - 0.01, hy - 0.01))],
        cav,
        [colour_name(c), "drop-down door", "pull-out dish rack"],
    )


@register("Microwave")
def microwave(rng):
    r = Part("root")
    hx, hy, hz, t = u(rng, 0.22, 0.28), u(rng, 0.17, 0.21), u(rng, 0.14, 0.17), 0.015
    c = colour(rng, APPLIANCE)
    _appliance_shell(r, hx, hy, 2 * hz, t, c)  # full height: hz is half of it
    pw = hx * 0.5
    r.box((pw / 2, 0.01, hz - 0.004), (hx - pw / 2, -hy - 0.01, hz), c, D_HOLLOW)  # control panel
    side_door(
        r,
        "door",
        -hx + 0.004,
        hx - pw - 0.004,
        0.004,
        2 * hz - 0.004,
        -hy,
        True,
        c,
        D_HOLLOW,
        thick=0.025,
        handle=False,
    )
    r.children[-1].box(
        ((hx * 2 - pw) / 2 * 0.7, 0.001, hz * 0.6),
        ((2 * hx - pw) / 2, -0.026, 0),
        BLACK_GLASS,
        100,
        collide=False,
    )
    r.children[-1].box((0.01, 0.01, hz * 0.5), (2 * hx - pw - 0.03, -0.035, 0), DARK, 900)
    knob(r, "knob_0", (hx - pw / 2, -hy - 0.02, hz * 1.3), 0.015, DARK)
    r.cyl(hx * 0.4, 0.004, (-pw / 2, 0, t + 0.005), GLASS, 2500)
    cav = [
        Cavity(
            "inside",
            (-pw / 2, 0, hz),
            (hx - pw / 2 - 1.5 * t, hy - 1.5 * t, hz - 1.5 * t),
            "front",
            "door_hinge",
        )
    ]
    return Draft(
        r,
        {},
        [Surface("top", (0, 0, 2 * hz), (hx - 0.01, hy - 0.01))],
        cav,
        [colour_name(c), "side-hinged door", "turntable"],
    )


@register("WashingMachine")
def washing_machine(rng):
    r = Part("root")
    hx, hy, h, t = u(rng, 0.29, 0.31), u(rng, 0.27, 0.31), u(rng, 0.82, 0.88), 0.03
    c = colour(rng, APPLIANCE[:2])
    top_loader = rng.random() < 0.3
    cav = []
    if top_loader:
        open_box(r, hx, hy, h / 2 - 0.01, t, c, D_HOLLOW)
        top_lid(r, "lid", hx, hy, h - 0.02, c, D_HOLLOW, thick=0.02)
        cav.append(Cavity("drum", (0, 0, h / 2), (hx * 0.7, hy * 0.7, h / 2 - 0.06), "top", "lid_hinge"))
        feats = ["top-loading lid"]
    else:
        _appliance_shell(r, hx, hy, h, t, c)
        d = side_door(
            r,
            "door",
            -hx * 0.6,
            hx * 0.6,
            h * 0.2,
            h * 0.75,
            -hy,
            True,
            c,
            D_HOLLOW,
            thick=0.03,
            handle=False,
        )
        d.cyl(hx * 0.45, 0.005, (hx * 0.6, -0.035, 0), GLASS, 2500, axis="y", collide=False)
        d.cyl(hx * 0.55, 0.012, (hx * 0.6, -0.02, 0), WHITE, D_HOLLOW, axis="y")
        cav.append(Cavity("drum", (0, 0, h * 0.48), (hx * 0.6, hy * 0.7, h * 0.25), "front", "door_hinge"))
        feats = ["round front door"]
    knob(r, "knob_0", (hx * 0.6, -hy - 0.005, h * 0.9), 0.03, DARK)
    return Draft(
        r,
        {"top_loader": top_loader},
        [Surface("top", (0, 0, h), (hx - 0.01, hy - 0.01))] if not top_loader else [],
        cav,
        [colour_name(c)] + feats,
    )


@register("Safe")
def safe(rng):
    r = Part("root")
    hx, hy, hz, t = u(rng, 0.15, 0.3), u(rng, 0.15, 0.25), u(rng, 0.15, 0.3), 0.03
    c = colour(rng, [DARK, METAL[2], (0.25, 0.3, 0.25, 1), APPLIANCE[1]])
    open_box(r, hx, hy, hz, t, c, 1500, top=True, front=False)
    d = side_door(r, "door", -hx + 0.004, hx - 0.004, 0.004, 2 * hz - 0.004, -hy, True, c, 2000, thick=0.04)
    knob(d, "dial", (hx, -0.04, hz * 0.3), min(hx, hz) * 0.2, METAL[0], label=DIAL)
    cav = [Cavity("inside", (0, 0, hz), (hx - 1.5 * t, hy - 1.5 * t, hz - 1.5 * t), "front", "door_hinge")]
    return Draft(
        r,
        {},
        [Surface("top", (0, 0, 2 * hz), (hx - 0.01, hy - 0.01))],
        cav,
        [colour_name(c), "heavy steel door", "combination dial", "locks away valuables and medicine"],
    )


@register("Door")
def door(rng):
    r = Part("root")
    w, h, t = u(rng, 0.8, 0.95), u(rng, 1.95, 2.05), u(rng, 0.035, 0.045)
    c = colour(rng, WOOD + [WHITE])
    fc = colour(rng, [WHITE, WOOD[2]])
    r.box((w / 2 + 0.1, 0.25, 0.005), (0, 0, 0.005), fc, D_WOOD)  # floor plate standing in for the wall
    fw = 0.05
    for s in (-1, 1):
        r.box((fw / 2, 0.06, h / 2), (s * (w / 2 + fw / 2), 0, h / 2 + 0.01), fc, D_WOOD)
    r.box((w / 2 + fw, 0.06, fw / 2), (0, 0, h + 0.01 + fw / 2), fc, D_WOOD)
    left = bool(rng.random() < 0.5)
    d = side_door(
        r,
        "door",
        -w / 2 + 0.004,
        w / 2 - 0.004,
        0.02,
        h,
        t / 2 + 0.002,
        left,
        c,
        D_WOOD,
        thick=t,
        handle=False,
        open_angle=1.75,
    )
    sx = 1 if left else -1
    d.segment((sx * (w - 0.08), -t - 0.04, 0), (sx * (w - 0.2), -t - 0.04, 0), 0.01, METAL[0], D_METAL)
    d.segment((sx * (w - 0.08), -t, 0), (sx * (w - 0.08), -t - 0.04, 0), 0.008, METAL[0], D_METAL)
    if rng.random() < 0.4:
        d.box((w * 0.3, 0.001, h * 0.2), (sx * w / 2, -t - 0.001, h * 0.2), GLASS, 100, collide=False)
    return Draft(r, {"left_hinged": left}, [], [], [colour_name(c), "hinged door leaf", "lever handle"])


@register("Window")
def window(rng):
    r = Part("root")
    w, h = u(rng, 0.7, 1.2), u(rng, 0.8, 1.3)
    fc = colour(rng, [WHITE, WOOD[0], DARK])
    fw, depth = 0.05, 0.1
    r.box((w / 2 + fw, 0.2, 0.02), (0, 0, 0.02), fc, D_WOOD)  # sill block standing in for the wall
    for s in (-1, 1):
        r.box((fw / 2, depth / 2, h / 2), (s * (w / 2 + fw / 2), 0, 0.04 + h / 2), fc, D_WOOD)
    r.box((w / 2 + fw, depth / 2, fw / 2), (0, 0, 0.04 + h + fw / 2), fc, D_WOOD)
    sliding = bool(rng.random() < 0.5)
    zc = 0.04 + h / 2
    if sliding:
        r.box((w / 4, 0.012, h / 2 - 0.01), (w / 4, 0.02, zc), GLASS, 300)  # fixed pane at the back track
        r.box((0.01, 0.015, h / 2 - 0.01), (w / 2 - 0.01, 0.02, zc), fc, D_WOOD)
        s = r.child("sash", (-w / 4, -0.02, zc))
        s.slide("sash_slide", (1, 0, 0), (0, w / 2 - 0.02), SASH, 0.0)
        s.box((w / 4 - 0.004, 0.012, h / 2 - 0.01), (0, 0, 0), GLASS, 300)
        for sx in (-1, 1):
            s.box((0.012, 0.016, h / 2 - 0.01), (sx * (w / 4 - 0.012), 0, 0), fc, D_WOOD)
        feats = ["sliding sash"]
    else:
        s = r.child("sash", (-w / 2, -depth / 2 + 0.012, zc))
        s.hinge("sash_hinge", (0, 0, 1), (-1.5, 0), SASH, 0.0)
        s.box((w / 2 - 0.004, 0.012, h / 2 - 0.004), (w / 2, 0, 0), GLASS, 300)
        for sz in (-1, 1):
            s.box((w / 2 - 0.004, 0.016, 0.02), (w / 2, 0, sz * (h / 2 - 0.02)), fc, D_WOOD)
        s.box((0.01, 0.02, 0.05), (w - 0.04, -0.03, 0), METAL[0], D_METAL)
        feats = ["hinged casement sash"]
    return Draft(
        r,
        {"sliding": sliding},
        [Surface("sill", (0, -0.1, 0.04), (w / 2, 0.08))],
        [],
        feats + ["glass panes", "open window lets air in, fall risk"],
    )


@register("Table")
def table(rng):
    r = Part("root")
    hx, hy, h = u(rng, 0.4, 0.75), u(rng, 0.3, 0.45), u(rng, 0.7, 0.78)
    c = colour(rng, WOOD + [WHITE])
    t = 0.025
    r.box((hx, hy, t / 2), (0, 0, h - t / 2), c, D_WOOD)
    leg = pick(rng, ["square", "round"])
    for sx in (-1, 1):
        for sy in (-1, 1):
            p = (sx * (hx - 0.05), sy * (hy - 0.05))
            if leg == "square":
                r.box((0.022, 0.022, (h - t) / 2), (p[0], p[1], (h - t) / 2), c, D_WOOD)
            else:
                r.cyl(0.022, (h - t) / 2, (p[0], p[1], (h - t) / 2), c, D_WOOD)
    r.box((hx - 0.07, 0.01, 0.04), (0, -hy + 0.05, h - t - 0.04), c, D_WOOD)
    cav, feats = [], [colour_name(c), f"{leg} legs"]
    if rng.random() < 0.4:
        _, cv = drawer(
            r, "drawer", -0.2, 0.2, h - t - 0.1, h - t - 0.005, -hy + 0.04, 2 * hy - 0.2, c, D_WOOD
        )
        cav.append(cv)
        feats.append("drawer under the top")
    return Draft(r, {"legs": leg}, [Surface("top", (0, 0, h), (hx - 0.02, hy - 0.02))], cav, feats)


def _chair_frame(r: Part, hw, hd, seat_h, c, leg_c, round_legs: bool):
    r.box((hw, hd, 0.02), (0, 0, seat_h - 0.02), c, D_WOOD)
    for sx in (-1, 1):
        for sy in (-1, 1):
            p = (sx * (hw - 0.025), sy * (hd - 0.025))
            if round_legs:
                r.cyl(0.015, (seat_h - 0.04) / 2, (p[0], p[1], (seat_h - 0.04) / 2), leg_c, D_WOOD)
            else:
                r.box((0.016, 0.016, (seat_h - 0.04) / 2), (p[0], p[1], (seat_h - 0.04) / 2), leg_c, D_WOOD)


@register("Chair")
def chair(rng):
    r = Part("root")
    hw, hd, seat_h, back_h = u(rng, 0.2, 0.25), u(rng, 0.2, 0.25), u(rng, 0.43, 0.48), u(rng, 0.38, 0.5)
    c = colour(rng, WOOD + FABRIC)
    leg_c = colour(rng, WOOD + [METAL[2]])
    _chair_frame(r, hw, hd, seat_h, c, leg_c, bool(rng.random() < 0.5))
    back = r.child("backrest", (0, hd - 0.02, seat_h))
    back.hinge("backrest_hinge", (1, 0, 0), (0, 1.3), "backrest", 0.0)
    tilt = 0.12
    back.box(
        (hw - 0.01, 0.015, back_h / 2),
        (0, 0.015 + back_h / 2 * math.sin(tilt), back_h / 2 + 0.01),
        c,
        D_WOOD,
        quat=(math.cos(tilt / 2), math.sin(tilt / 2), 0, 0),
    )
    return Draft(
        r,
        {"back_height": back_h},
        [Surface("seat", (0, -0.02, seat_h), (hw - 0.02, hd - 0.04))],
        [],
        [colour_name(c), "folding backrest", "children climb on it to reach high places"],
    )


@register("FoldingChair")
def folding_chair(rng):
    r = Part("root")
    hw, hd, seat_h, back_h = u(rng, 0.19, 0.23), u(rng, 0.19, 0.22), u(rng, 0.43, 0.47), u(rng, 0.35, 0.45)
    c = colour(rng, [METAL[2], DARK, WOOD[1]] + PLASTIC[:3])
    fr = colour(rng, METAL[:3])
    for sx in (-1, 1):  # X-shaped side frames
        r.segment((sx * hw, -hd, 0.01), (sx * hw, hd, seat_h - 0.03), 0.012, fr, D_METAL)
        r.segment((sx * hw, hd, 0.01), (sx * hw, -hd, seat_h - 0.03), 0.012, fr, D_METAL)
        r.segment((sx * hw, hd, seat_h - 0.03), (sx * hw, hd + 0.03, seat_h + back_h), 0.012, fr, D_METAL)
    r.box((hw, 0.012, back_h * 0.3), (0, hd + 0.025, seat_h + back_h * 0.65), c, 700)
    seat = r.child("seat", (0, hd - 0.01, seat_h - 0.015))
    seat.hinge("seat_hinge", (1, 0, 0), (-1.5, 0), "seat", 0.0)
    seat.box((hw - 0.02, hd - 0.01, 0.012), (0, -hd + 0.01, 0.012), c, 700)
    return Draft(
        r,
        {},
        [Surface("seat", (0, 0, seat_h + 0.01), (hw - 0.03, hd - 0.03))],
        [],
        [colour_name(c), "folding seat", "scissor metal frame", "can pinch fingers when folded"],
    )


@register("Toilet")
def toilet(rng):
    r = Part("root")
    bw, bd, bh = u(rng, 0.17, 0.2), u(rng, 0.24, 0.28), u(rng, 0.38, 0.42)
    c = colour(rng, [WHITE, (0.92, 0.92, 0.88, 1)])
    r.box((bw * 0.6, bd * 0.7, 0.04), (0, 0.02, 0.04), c, 1500)  # pedestal
    r.cyl(bw * 0.7, (bh - 0.08) / 2, (0, 0.0, 0.04 + (bh - 0.08) / 2), c, 600)
    r.ring(bw * 0.9, bh - 0.12, bh, 0.04, 14, c, 1500, center=(0, -0.02), ry=bd * 0.9)
    tank_w = bw * 1.0
    r.box((tank_w, 0.09, 0.2), (0, bd + 0.05, bh + 0.12), c, 800)
    r.box((tank_w + 0.01, 0.1, 0.012), (0, bd + 0.05, bh + 0.33), c, 800)
    lid = r.child("lid", (0, bd - 0.05, bh + 0.025))
    lid.hinge("lid_hinge", (1, 0, 0), (-1.75, 0), LID, 0.0)
    lid.ellipsoid((bw * 0.95, bd * 0.92, 0.01), (0, -bd * 0.92, 0), c, 900)
    seat = r.child("seat", (0, bd - 0.05, bh + 0.008))
    seat.hinge("seat_hinge", (1, 0, 0), (-1.65, 0), "seat", 0.0)
    n = 16
    for i in range(n):
        a = 2 * math.pi * i / n
        seat.box(
            (0.02, 0.032, 0.007),
            (bw * 0.8 * math.cos(a), -bd * 0.92 + bd * 0.8 * math.sin(a), 0),
            c,
            900,
            quat=(math.cos(a / 2), 0, 0, math.sin(a / 2)),
        )
    cav = [Cavity("bowl", (0, -0.02, bh - 0.08), (bw * 0.5, bd * 0.5, 0.07), "top", "lid_hinge")]
    return Draft(
        r,
        {},
        [Surface("tank_top", (0, bd + 0.05, bh + 0.342), (tank_w - 0.01, 0.08))],
        cav,
        ["white porcelain", "hinged lid and seat", "bowl of water, drowning risk for toddlers"],
    )


@register("TrashCan")
def trash_can(rng):
    r = Part("root")
    rad, h = u(rng, 0.13, 0.2), u(rng, 0.3, 0.6)
    c = colour(rng, METAL[:2] + PLASTIC)
    r.cyl(rad, 0.006, (0, 0, 0.006), c, 1200)
    r.ring(rad, 0.012, h, 0.008, 14, c, 1200)
    pedal = rng.random() < 0.6
    lid = r.child("lid", (0, rad + 0.005, h + 0.002))
    lid.hinge("lid_hinge", (1, 0, 0), (-1.6, 0), LID, 0.0)
    # a moulded shell, not 12 mm of solid plastic (which made a 2 kg lid on a 7 kg bin)
    lid.cyl(rad + 0.006, 0.006, (0, -rad - 0.005, 0.006), c, D_HOLLOW)
    feats = [colour_name(c), "hinged lid"]
    if pedal:
        p = r.child("pedal", (0, -rad + 0.02, 0.04))
        p.hinge("pedal_hinge", (1, 0, 0), (0, 0.35), "pedal", 0.0, spring=True)
        p.box((rad * 0.35, 0.04, 0.006), (0, -0.04, 0), DARK, 1500)
        feats.append("foot pedal")
    cav = [
        Cavity("inside", (0, 0, h / 2 + 0.006), (rad * 0.68, rad * 0.68, h / 2 - 0.02), "top", "lid_hinge")
    ]
    return Draft(r, {"pedal": pedal}, [], cav, feats + ["for rubbish and spoiled food"])


@register("Cart")
def cart(rng):
    r = Part("root")
    hx, hy, h = u(rng, 0.3, 0.45), u(rng, 0.2, 0.3), u(rng, 0.7, 0.95)
    c = colour(rng, METAL[:3] + PLASTIC[:3])
    wr = u(rng, 0.04, 0.06)
    n_shelves = int(rng.integers(2, 4))
    surfaces = []
    base = 2 * wr + 0.03
    for k in range(n_shelves):
        z = base + (h - base - 0.02) * k / max(1, n_shelves - 1)
        r.box((hx, hy, 0.01), (0, 0, z), c, 1200)
        surfaces.append(Surface(f"shelf_{k}", (0, 0, z + 0.01), (hx - 0.02, hy - 0.02)))
    for sx in (-1, 1):
        for sy in (-1, 1):
            r.cyl(
                0.012,
                (h - base) / 2,
                (sx * (hx - 0.015), sy * (hy - 0.015), base + (h - base) / 2),
                METAL[1],
                D_METAL,
            )
            r.box((0.012, 0.012, 0.012), (sx * (hx - 0.05), sy * (hy - 0.05), base - 0.02), METAL[1], D_METAL)
    r.segment((hx, -hy * 0.8, h + 0.02), (hx, hy * 0.8, h + 0.02), 0.012, DARK, 1000)
    for s in (-1, 1):
        r.segment((hx - 0.015, s * hy * 0.8, h), (hx, s * hy * 0.8, h + 0.02), 0.01, DARK, 1000)
    k = 0
    for sx in (-1, 1):
        for sy in (-1, 1):
            w = r.child(f"wheel_{k}", (sx * (hx - 0.05), sy * (hy - 0.05), wr))
            w.hinge(f"wheel_{k}_joint", (0, 1, 0), (-math.pi, math.pi), "wheel", 0.0)
            w.cyl(wr, 0.012, (0, 0, 0), DARK, 1200, axis="y")
            w.box((0.01, 0.005, 0.01), (0, 0, wr * 0.6), METAL[0], D_METAL, collide=False)
            r.box(
                (0.006, 0.016, (base - 0.02 - wr) / 2 + 0.01),
                (sx * (hx - 0.05), sy * (hy - 0.05) + 0.02 * sy, wr + (base - 0.02 - wr) / 2),
                METAL[1],
                D_METAL,
                collide=False,
            )
            k += 1
    return Draft(
        r,
        {"shelves": n_shelves},
        surfaces,
        [],
        [colour_name(c), f"{n_shelves} shelves", "four wheels", "push handle"],
    )
