"""Small hand-held targets: tools with hinged halves, electronics with lids and buttons, stationery.

Objects lie the way they rest on a table; joints on vertical axes (scissors, folding knife, USB cap,
eyeglass temples) feel no gravity, the others close under gravity or by a spring.
"""

from __future__ import annotations

import math

from anomalygen.assets.generators.appliances import button
from anomalygen.assets.generators.common import (
    BLACK_GLASS,
    D_METAL,
    D_PLASTIC,
    DARK,
    METAL,
    PLASTIC,
    WHITE,
    WOOD,
    colour,
    colour_name,
    pick,
    u,
)
from anomalygen.assets.model import Draft, Surface
from anomalygen.assets.parts import Part, axis_angle
from anomalygen.assets.registry import register
from anomalygen.schema import BUTTON, KNOB, LID


@register("Camera")
def camera(rng):
    r = Part("root")
    hx, hy, hz = u(rng, 0.055, 0.075), u(rng, 0.025, 0.04), u(rng, 0.035, 0.05)
    c = colour(rng, [DARK, METAL[0], (0.7, 0.6, 0.45, 1)])
    r.box((hx, hy, hz), (0, 0, hz), c, 900)
    lr = hz * u(rng, 0.55, 0.8)
    r.cyl(lr, 0.02, (0, -hy - 0.02, hz), DARK, 1500, axis="y")
    r.cyl(lr * 0.8, 0.001, (0, -hy - 0.041, hz), BLACK_GLASS, 100, axis="y", collide=False)
    lens = r.child("lens_ring", (0, -hy - 0.02, hz))
    lens.hinge("zoom_ring", (0, -1, 0), (0, 1.5), KNOB, 0.0)
    lens.cyl(lr * 1.08, 0.006, (0, 0, 0), METAL[2], 1500, axis="y")
    button(r, "shutter", (hx * 0.6, 0, 2 * hz + 0.003), (0.007, 0.007, 0.003), METAL[0], travel=0.003)
    return Draft(r, {}, [], [], [colour_name(c), "lens", "shutter button"])


@register("Eyeglasses")
def eyeglasses(rng):
    r = Part("root")
    lr, bridge, tl = u(rng, 0.022, 0.028), u(rng, 0.008, 0.012), u(rng, 0.12, 0.14)
    c = colour(rng, [DARK, METAL[0], (0.45, 0.25, 0.1, 1), (0.7, 0.2, 0.3, 1)])
    w = 2 * lr + bridge
    z = lr + 0.004
    for s in (-1, 1):
        r.cyl(lr, 0.0015, (s * (lr + bridge / 2), 0, z), (0.8, 0.9, 0.95, 0.35), 1200, axis="y")
        r.box((lr, 0.003, 0.002), (s * (lr + bridge / 2), 0, z + lr), c, 1200)
        r.box((lr, 0.003, 0.002), (s * (lr + bridge / 2), 0, z - lr), c, 1200)
    r.box((bridge / 2 + 0.002, 0.003, 0.002), (0, 0, z + lr * 0.5), c, 1200)
    for s, name in ((-1, "left_temple"), (1, "right_temple")):
        t = r.child(name, (s * w, 0.002, z + lr * 0.5))
        t.hinge(
            f"{name}_hinge", (0, 0, 1), (-1.5, 0) if s < 0 else (0, 1.5), "temple", -1.5 if s < 0 else 1.5
        )
        t.box((0.0015, tl / 2, 0.002), (0, tl / 2, 0), c, 1200)
        drop = (z + lr * 0.5) - (z - lr - 0.002)  # ear piece reaches down to the rims' bottom level
        t.box((0.0015, 0.004, drop / 2), (0, tl, -drop / 2), c, 1200)
    return Draft(r, {}, [], [], [colour_name(c), "two lenses", "folding temples", "fragile"])


@register("Keyboard")
def keyboard(rng):
    r = Part("root")
    hx, hy = u(rng, 0.15, 0.22), u(rng, 0.05, 0.08)
    c = colour(rng, [DARK, WHITE, METAL[1]])
    kc = (0.12, 0.12, 0.13, 1) if sum(c[:3]) > 1.5 else (0.85, 0.85, 0.86, 1)  # keys contrast with the body
    r.box((hx, hy, 0.008), (0, 0, 0.008), c, 1000)
    rows, cols = 4, int((2 * hx - 0.012) / 0.019)
    for i in range(rows):
        for j in range(cols):
            if i == 0 and cols // 2 - 3 <= j <= cols // 2 + 3:
                continue
            r.box(
                (0.0075, 0.0075, 0.003),
                (-hx + 0.012 + j * 0.019, -hy + 0.015 + i * 0.019, 0.019),
                kc,
                900,
                collide=False,
            )
    sp = r.child("space_bar", (0, -hy + 0.015, 0.019))
    sp.slide("space_bar_press", (0, 0, -1), (0, 0.003), "key", 0.0, spring=True)
    sp.box((0.065, 0.0075, 0.003), (0, 0, 0), kc, 900)
    return Draft(r, {"columns": cols}, [], [], [colour_name(c), "keys", "space bar"])


@register("Knife")
def folding_knife(rng):
    r = Part("root")
    hl, bl, hw = u(rng, 0.09, 0.12), u(rng, 0.07, 0.1), u(rng, 0.01, 0.014)
    c = colour(rng, [DARK, WOOD[0], WOOD[2], PLASTIC[0], METAL[2]])
    r.box((hl / 2, hw, 0.006), (0, 0, 0.006), c, 1200)
    bl_ = r.child("blade", (hl / 2 - 0.006, 0, 0.006))
    bl_.hinge("blade_hinge", (0, 0, 1), (0, math.pi), "blade", 0.0)
    # folded (0): the blade lies back along the handle; open (pi): it sticks out beyond the end
    bl_.box((bl / 2, hw * 0.8, 0.0012), (-bl / 2, 0.001, 0.0), METAL[0], D_METAL, name="blade")
    bl_.box(
        (bl * 0.1, hw * 0.5, 0.0012),
        (-bl * 1.02, -hw * 0.25, 0.0),
        METAL[0],
        D_METAL,
        quat=axis_angle((0, 0, 1), 0.5),
    )
    return Draft(
        r, {"blade": bl}, [], [], [colour_name(c), "folding pocket knife", "sharp blade that swings out"]
    )


@register("Laptop")
def laptop(rng):
    r = Part("root")
    hx, hy = u(rng, 0.15, 0.19), u(rng, 0.1, 0.13)
    c = colour(rng, [METAL[0], METAL[2], DARK, WHITE])
    r.box((hx, hy, 0.008), (0, 0, 0.008), c, 1600)
    r.box((hx * 0.85, hy * 0.45, 0.001), (0, hy * 0.3, 0.0165), DARK, 100, collide=False)  # keyboard area
    r.box(
        (hx * 0.25, hy * 0.2, 0.0005),
        (0, -hy * 0.6, 0.016),
        (c[0] * 0.9, c[1] * 0.9, c[2] * 0.9, 1),
        100,
        collide=False,
    )
    lid = r.child("screen", (0, hy, 0.017))
    lid.hinge("screen_hinge", (1, 0, 0), (-2.0, 0), "hinge", 0.0)
    lid.box((hx, hy, 0.004), (0, -hy, 0.004), c, 1400)
    lid.box((hx * 0.92, hy * 0.88, 0.0005), (0, -hy, -0.0005), BLACK_GLASS, 100, collide=False)
    return Draft(
        r,
        {},
        [Surface("lid_top", (0, 0, 0.025), (hx - 0.01, hy - 0.01))],
        [],
        [colour_name(c), "hinged screen lid", "fragile electronics"],
    )


@register("Mouse")
def mouse(rng):
    r = Part("root")
    L, w = u(rng, 0.05, 0.06), u(rng, 0.028, 0.034)
    c = colour(rng, [DARK, WHITE, METAL[1]] + PLASTIC[:2])
    r.ellipsoid((w, L, 0.018), (0, 0.005, 0.012), c, 600)
    for s, name in ((-1, "left_button"), (1, "right_button")):
        b = r.child(name, (s * w * 0.45, -L * 0.1, 0.026))
        b.hinge(f"{name}_click", (1, 0, 0), (0, 0.05), BUTTON, 0.0, pos=(0, L * 0.5, 0), spring=True)
        b.ellipsoid((w * 0.42, L * 0.45, 0.004), (0, -L * 0.3, 0), c, 600)
    wh = r.child("wheel", (0, -L * 0.3, 0.029))
    wh.hinge("wheel_spin", (1, 0, 0), (-math.pi, math.pi), "wheel", 0.0)
    wh.cyl(0.006, 0.002, (0, 0, 0), DARK, 1200, axis="x")
    return Draft(r, {}, [], [], [colour_name(c), "two buttons", "scroll wheel"])


@register("Pen")
def pen(rng):
    r = Part("root")
    L, rad = u(rng, 0.12, 0.14), u(rng, 0.004, 0.006)
    c = colour(rng, PLASTIC + METAL[:1])
    r.box((L / 2, rad, rad), (0, 0, rad), c, 1100)
    r.cyl(rad * 0.5, 0.006, (L / 2 + 0.006, 0, rad), METAL[0], D_METAL, axis="x")
    cap_kind = pick(rng, ["cap", "click"])
    if cap_kind == "cap":
        cp = r.child("cap", (L / 2 - 0.025, 0, rad))
        cp.slide("cap_slide", (1, 0, 0), (0, 0.05), "cap", 0.0)
        cp.box((0.03, rad * 1.2, rad * 1.2), (0.03, 0, 0), c, 1100)
        cp.box((0.02, 0.0015, 0.002), (0.02, 0, rad * 1.4), METAL[0], D_METAL)
    else:
        b = r.child("click", (-L / 2, 0, rad))
        b.slide("click_press", (1, 0, 0), (0, 0.004), BUTTON, 0.0, spring=True)
        b.cyl(rad * 0.6, 0.006, (-0.006, 0, 0), METAL[0], D_METAL, axis="x")
    return Draft(
        r,
        {"kind": cap_kind},
        [],
        [],
        [colour_name(c), "pen with a cap" if cap_kind == "cap" else "click pen", "pointed tip"],
    )


@register("Phone")
def phone(rng):
    r = Part("root")
    hx, hy = u(rng, 0.033, 0.04), u(rng, 0.07, 0.082)
    c = colour(rng, [DARK, WHITE, METAL[0], (0.3, 0.4, 0.6, 1)])
    r.box((hx, hy, 0.004), (0, 0, 0.004), c, 2000)
    r.box((hx * 0.93, hy * 0.95, 0.0005), (0, 0, 0.0085), BLACK_GLASS, 100, collide=False)
    b = r.child("side_button", (hx + 0.001, hy * 0.3, 0.004))
    b.slide("side_button_press", (-1, 0, 0), (0, 0.001), BUTTON, 0.0, spring=True)
    b.box((0.001, 0.008, 0.0015), (0, 0, 0), c, 2000)
    return Draft(r, {}, [], [], [colour_name(c), "smartphone", "glass touch screen"])


def _hinged_pair(rng, kind: str):
    """Two crossing halves on a pivot at the origin: blade/jaw ahead (+x), handle behind (-x)."""
    r = Part("root")
    scissors = kind == "Scissors"
    bl, hl = (u(rng, 0.06, 0.1), u(rng, 0.06, 0.08)) if scissors else (u(rng, 0.035, 0.05), u(rng, 0.1, 0.14))
    hc = colour(rng, PLASTIC[:4] + [DARK])
    a = 0.12  # each half's blade leans this far off the axis; the handles splay the other way
    thick = 0.004  # blade and handle share one thickness so the lower half lies flat
    dens = D_PLASTIC if scissors else D_METAL

    def half(part: Part, side: int, z: float, blade_name=None):
        q = axis_angle((0, 0, 1), side * a)
        c, s_ = math.cos(side * a), math.sin(side * a)
        bw = 0.006 if scissors else 0.009
        part.box(
            (bl / 2, bw, thick), (bl / 2 * c, bl / 2 * s_, z), METAL[0], D_METAL, quat=q, name=blade_name
        )
        qh = axis_angle((0, 0, 1), -side * 2.5 * a)
        ch, sh = math.cos(-side * 2.5 * a), math.sin(-side * 2.5 * a)
        part.box((hl / 2, 0.006, 0.004), (-hl / 2 * ch, -hl / 2 * sh, z), hc, dens, quat=qh)
        end = (-hl * ch, -hl * sh)
        if scissors:  # finger loop
            part.ring(
                0.013,
                z - 0.004,
                z + 0.004,
                0.004,
                8,
                hc,
                dens,
                center=(end[0] - 0.011 * ch, end[1] - 0.011 * sh),
            )
        else:  # rubber grip
            part.box((hl * 0.3, 0.009, 0.004), (end[0] * 0.7, end[1] * 0.7, z), hc, 1100, quat=qh)

    half(r, 1, thick, "blade")
    up = r.child("upper_half", (0, 0, 0))
    up.hinge("pivot", (0, 0, 1), (0, 0.6), "blade" if scissors else "handle", 0.0)
    half(
        up, -1, thick + 0.0005
    )  # same level as the lower half (own-part contacts are excluded): both lie flat
    r.cyl(0.005, 0.004, (0, 0, 2 * thick + 0.001), METAL[2], D_METAL)
    feats = [colour_name(hc), "two hinged halves"]
    feats += (
        ["sharp pointed blades", "finger loops"]
        if scissors
        else ["metal gripping jaws", "rubber grips", "can pinch"]
    )
    return Draft(r, {"blade": bl}, [], [], feats)


register("Scissors")(lambda rng: _hinged_pair(rng, "Scissors"))
register("Pliers")(lambda rng: _hinged_pair(rng, "Pliers"))


@register("Remote")
def remote(rng):
    r = Part("root")
    hx, hy = u(rng, 0.022, 0.028), u(rng, 0.07, 0.1)
    c = colour(rng, [DARK, WHITE, METAL[1]])
    r.box((hx, hy, 0.01), (0, 0, 0.01), c, 1000)
    n = int(rng.integers(2, 5))
    for k in range(n):
        button(
            r,
            f"button_{k}",
            (0, hy * 0.6 - k * 0.02, 0.0215),
            (hx * 0.5, 0.006, 0.0015),
            pick(rng, [(0.8, 0.2, 0.2, 1), (0.6, 0.6, 0.6, 1), (0.2, 0.6, 0.3, 1)]),
            travel=0.0015,
        )
    for i in range(3):
        for j in range(3):
            r.box(
                (0.004, 0.004, 0.001),
                (-0.01 + 0.01 * i, -hy * 0.5 + 0.01 * j, 0.0205),
                (0.7, 0.7, 0.7, 1),
                100,
                collide=False,
            )
    return Draft(r, {"buttons": n}, [], [], [colour_name(c), f"{n} push buttons", "contains batteries"])


@register("Stapler")
def stapler(rng):
    r = Part("root")
    L, w = u(rng, 0.06, 0.09), u(rng, 0.015, 0.02)
    c = colour(rng, [DARK, (0.8, 0.15, 0.15, 1), METAL[1], (0.2, 0.3, 0.7, 1)])
    r.box((L, w, 0.005), (0, 0, 0.005), c, 1500)
    r.box((0.012, w * 0.7, 0.012), (-L + 0.012, 0, 0.02), c, 1500)
    arm = r.child("arm", (-L + 0.012, 0, 0.032))
    arm.hinge("arm_hinge", (0, 1, 0), (-1.0, 0), LID, 0.0)
    arm.box((L * 0.97, w * 0.9, 0.009), (L * 0.97, 0, -0.0), c, 1500)
    return Draft(r, {}, [], [], [colour_name(c), "hinged top arm", "can pinch fingers", "staples are sharp"])


@register("USB")
def usb(rng):
    r = Part("root")
    L, w = u(rng, 0.025, 0.035), u(rng, 0.008, 0.011)
    c = colour(rng, PLASTIC + [DARK])
    r.box((L / 2, w, 0.004), (0, 0, 0.004), c, 1200)
    r.box((0.006, w * 0.65, 0.0023), (L / 2 + 0.006, 0, 0.004), METAL[0], D_METAL)
    cap = r.child("cap", (-L / 2 + 0.003, 0, 0.004))
    cap.hinge("cap_swivel", (0, 0, 1), (0, math.pi), "cap", math.pi)
    # at 0 the swivel cover lies back along the body; at pi it covers the connector (closed/safe)
    cap.box((L / 2 + 0.004, 0.0006, 0.0045), (-(L / 2 + 0.004), w + 0.001, 0), METAL[1], D_METAL)
    cap.box((L / 2 + 0.004, 0.0006, 0.0045), (-(L / 2 + 0.004), -w - 0.001, 0), METAL[1], D_METAL)
    cap.box((0.0006, w + 0.0016, 0.0045), (-(L + 0.008), 0, 0), METAL[1], D_METAL)
    return Draft(r, {}, [], [], [colour_name(c), "USB flash drive", "swivel cap"])


@register("Lighter")
def lighter(rng):
    r = Part("root")
    hx, hy, h = u(rng, 0.017, 0.02), u(rng, 0.006, 0.009), u(rng, 0.045, 0.06)
    c = colour(rng, METAL[:2] + PLASTIC[:4])
    r.box((hx, hy, h / 2), (0, 0, h / 2), c, 1500)
    r.cyl(0.004, 0.003, (-hx * 0.3, 0, h + 0.003), METAL[1], D_METAL)
    wheel = r.child("wheel", (hx * 0.4, 0, h + 0.005))
    wheel.hinge("wheel_spin", (0, 1, 0), (-math.pi, math.pi), "wheel", 0.0)
    wheel.cyl(0.0045, 0.003, (0, 0, 0), METAL[2], D_METAL, axis="y")
    lid = r.child("lid", (hx, 0, h + 0.0005))
    lid.hinge("lid_hinge", (0, 1, 0), (0, 2.0), LID, 0.0)
    lid.box((hx, hy, 0.008), (-hx, 0, 0.008), c, 1500)
    return Draft(r, {}, [], [], [colour_name(c), "flip lid", "flame: fire risk, keep away from children"])
