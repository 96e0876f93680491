"""Mid-sized targets: kitchen appliances, containers with lids, fan, lamp, globe, clock, luggage."""

from __future__ import annotations

import math

from anomalygen.assets.generators.common import (
    APPLIANCE,
    BLACK_GLASS,
    D_HOLLOW,
    D_METAL,
    D_PLASTIC,
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
from anomalygen.assets.generators.parts_lib import knob, side_door, top_lid
from anomalygen.assets.model import Cavity, Draft, Surface
from anomalygen.assets.parts import Part, axis_angle
from anomalygen.assets.registry import register
from anomalygen.schema import BUTTON, DRAWER, FLAP, LID
from anomalygen.schema.part_labels import HANDLE_GEOM


def button(parent: Part, name, pos, half, rgba, axis=(0, 0, -1), travel=0.004, label=BUTTON):
    """A spring-returned push button moving ``travel`` along ``axis`` when pressed."""
    b = parent.child(name, pos)
    b.slide(f"{name}_press", axis, (0, travel), label, 0.0, spring=True)
    b.box(half, (0, 0, 0), rgba, 900)
    return b


@register("CoffeeMachine")
def coffee_machine(rng):
    r = Part("root")
    hx, hy, h = u(rng, 0.1, 0.15), u(rng, 0.14, 0.2), u(rng, 0.3, 0.4)
    c = colour(rng, APPLIANCE + [(0.6, 0.1, 0.1, 1)])
    r.box((hx, hy, 0.02), (0, 0, 0.02), c, D_HOLLOW)  # base
    r.box(
        (hx, hy * 0.45, h / 2 - 0.02), (0, hy * 0.55, h / 2 + 0.02 - 0.02), c, D_HOLLOW
    )  # tower at the back
    r.box((hx, hy * 0.5, 0.04), (0, -hy * 0.2, h - 0.04), c, D_HOLLOW)  # head
    r.cyl(0.012, 0.02, (0, -hy * 0.4, h - 0.1), METAL[1], D_METAL)  # spout
    tray = r.child("drip_tray", (0, -hy + 0.005, 0.045))
    tray.slide("drip_tray_slide", (0, -1, 0), (0, hy * 0.6), DRAWER, 0.0)
    tray.box((hx * 0.8, hy * 0.4, 0.006), (0, hy * 0.4, 0.006), METAL[0], D_METAL)
    lid = top_lid(r, "lid", hx * 0.8, hy * 0.3, h, DARK, 900)
    lid.pos = (0, hy * 0.95, h)
    button(
        r, "power_button", (hx * 0.5, -hy * 0.7 + 0.02, h + 0.004), (0.012, 0.012, 0.004), (0.2, 0.8, 0.3, 1)
    )
    return Draft(
        r,
        {},
        [Surface("cup_tray", (0, -hy * 0.4, 0.052), (hx * 0.6, hy * 0.25))],
        [],
        [colour_name(c), "hinged water tank lid", "pull-out drip tray", "hot water and steam"],
    )


@register("Dispenser")
def dispenser(rng):
    r = Part("root")
    rad, h = u(rng, 0.03, 0.045), u(rng, 0.12, 0.18)
    c = colour(rng, PLASTIC + [GLASS])
    r.cyl(rad, h / 2, (0, 0, h / 2), c, 700)
    r.cyl(0.008, 0.015, (0, 0, h + 0.015), WHITE, 900)
    pump = r.child("pump", (0, 0, h + 0.035))
    pump.slide("pump_press", (0, 0, -1), (0, 0.012), "pump", 0.0, spring=True)
    pump.cyl(0.012, 0.008, (0, 0, 0.008), WHITE, 900)
    pump.box((0.022, 0.006, 0.005), (0, -0.025, 0.013), WHITE, 900)
    return Draft(r, {}, [], [], [colour_name(c), "pump head", "liquid soap or lotion, toxic if swallowed"])


@register("Display")
def display(rng):
    r = Part("root")
    w, hgt, neck = u(rng, 0.22, 0.35), u(rng, 0.15, 0.22), u(rng, 0.1, 0.18)
    c = colour(rng, [DARK, WHITE, METAL[1]])
    r.box((w * 0.35, 0.1, 0.01), (0, 0.02, 0.01), c, 3000)
    r.box((0.025, 0.012, neck / 2), (0, 0.05, 0.02 + neck / 2), c, 1500)
    scr = r.child("screen", (0, 0.03, 0.02 + neck))
    scr.hinge("screen_tilt", (1, 0, 0), (-0.35, 0.25), "hinge", 0.0, hold=True)
    scr.box((w, 0.015, hgt), (0, -0.01, hgt * 0.6), c, 600)
    scr.box((w * 0.95, 0.001, hgt * 0.92), (0, -0.026, hgt * 0.6), BLACK_GLASS, 100, collide=False)
    return Draft(
        r, {}, [], [], [colour_name(c), "computer monitor", "tilting screen", "top-heavy, can tip over"]
    )


@register("Printer")
def printer(rng):
    r = Part("root")
    hx, hy, hz = u(rng, 0.18, 0.24), u(rng, 0.15, 0.2), u(rng, 0.08, 0.14)
    c = colour(rng, APPLIANCE)
    r.box((hx, hy, hz), (0, 0, hz), c, D_HOLLOW)
    top_lid(r, "scanner_lid", hx, hy, 2 * hz, c, D_HOLLOW, thick=0.015, open_angle=1.3)
    tray = r.child("output_tray", (0, -hy - 0.002, hz * 0.5))
    tray.hinge("output_tray_hinge", (1, 0, 0), (0, 1.5), "tray", 0.0, spring=True)
    tray.box((hx * 0.7, 0.004, hz * 0.4), (0, -0.004, hz * 0.4), c, D_PLASTIC)
    button(r, "power_button", (hx * 0.7, -hy * 0.8, 2 * hz + 0.02), (0.008, 0.008, 0.003), (0.3, 0.7, 0.3, 1))
    return Draft(
        r,
        {},
        [Surface("lid_top", (0, 0, 2 * hz + 0.015), (hx - 0.01, hy - 0.01))],
        [],
        [colour_name(c), "scanner lid", "fold-down paper tray"],
    )


@register("Toaster")
def toaster(rng):
    r = Part("root")
    hx, hy, hz = u(rng, 0.12, 0.16), u(rng, 0.07, 0.1), u(rng, 0.09, 0.11)
    c = colour(rng, APPLIANCE + [(0.8, 0.15, 0.15, 1), METAL[0]])
    r.box((hx, hy, hz), (0, 0, hz), c, D_HOLLOW)
    slots = int(pick(rng, [1, 2, 2]))
    for k in range(slots):
        y = 0 if slots == 1 else (-1) ** k * hy * 0.4
        r.box((hx * 0.75, 0.012, 0.0015), (0, y, 2 * hz + 0.0015), DARK, 100, collide=False)
    lever = r.child("lever", (hx + 0.005, 0, 2 * hz - 0.02))
    lever.slide("lever_press", (0, 0, -1), (0, hz * 1.0), "lever", 0.0, spring=True)
    lever.box((0.015, 0.012, 0.008), (0.015, 0, 0), DARK, 900)
    knob(r, "knob_0", (hx + 0.002, 0, hz * 0.6), 0.012, DARK, axis=(1, 0, 0))
    return Draft(
        r,
        {"slots": slots},
        [],
        [Cavity("slot", (0, 0, hz * 1.5), (hx * 0.7, 0.01, hz * 0.45), "top")],
        [colour_name(c), f"{slots * 2} bread slots", "push-down lever", "hot when on"],
    )


@register("Kettle")
def kettle(rng):
    r = Part("root")
    rad, h = u(rng, 0.07, 0.09), u(rng, 0.16, 0.22)
    c = colour(rng, METAL[:2] + [WHITE, DARK, (0.8, 0.2, 0.2, 1)])
    r.cyl(rad * 1.05, 0.01, (0, 0, 0.01), DARK, 1500)  # power base
    r.ring(rad, 0.02, h, 0.006, 14, c, 1500)
    r.cyl(rad, 0.004, (0, 0, 0.024), c, 1500)
    r.segment((rad * 0.8, 0, h * 0.35), (rad + 0.06, 0, h * 0.95), 0.012, c, 1500)  # spout
    r.segment((-rad, 0, h * 0.9), (-rad - 0.05, 0, h * 0.85), 0.012, DARK, 1100)
    r.segment((-rad - 0.05, 0, h * 0.85), (-rad - 0.05, 0, h * 0.3), 0.012, DARK, 1100)
    r.segment((-rad - 0.05, 0, h * 0.3), (-rad, 0, h * 0.25), 0.012, DARK, 1100)
    lid = r.child("lid", (-rad * 0.8, 0, h + 0.002))
    lid.hinge("lid_hinge", (0, 1, 0), (-1.7, 0), LID, 0.0)
    lid.cyl(rad * 0.75, 0.006, (rad * 0.8, 0, 0.006), c, 1500)
    lid.box((0.012, 0.008, 0.01), (rad * 1.3, 0, 0.018), DARK, 1100)
    button(r, "switch", (-rad - 0.05, 0, h * 0.3 - 0.02), (0.008, 0.006, 0.004), (0.9, 0.4, 0.1, 1))
    cav = [Cavity("inside", (0, 0, h / 2 + 0.02), (rad * 0.65, rad * 0.65, h / 2 - 0.03), "top", "lid_hinge")]
    return Draft(
        r, {}, [], cav, [colour_name(c), "hinged lid", "spout and handle", "boiling water, burn risk"]
    )


@register("KitchenPot")
def kitchen_pot(rng):
    r = Part("root")
    rad, h = u(rng, 0.09, 0.13), u(rng, 0.08, 0.14)
    c = colour(rng, METAL[:3] + [(0.7, 0.2, 0.15, 1)])
    r.cyl(rad, 0.004, (0, 0, 0.004), c, D_METAL)
    r.ring(rad, 0.008, h, 0.004, 16, c, D_METAL)
    two = rng.random() < 0.6
    if two:
        for s in (-1, 1):
            r.box((0.02, 0.03, 0.006), (s * (rad + 0.02), 0, h * 0.85), DARK, 1100)
    else:
        r.box((0.08, 0.012, 0.008), (rad + 0.08, 0, h * 0.85), DARK, 1100, name=HANDLE_GEOM)  # turned by world/states.py
    lid = r.child("lid", (0, 0, h + 0.001))
    lid.slide("lid_lift", (0, 0, 1), (0, 0.12), LID, 0.0)
    lid.cyl(rad + 0.004, 0.003, (0, 0, 0.003), GLASS if rng.random() < 0.5 else c, 2500)
    lid.cyl(0.015, 0.01, (0, 0, 0.016), DARK, 1100)
    cav = [Cavity("inside", (0, 0, h / 2 + 0.004), (rad * 0.7, rad * 0.7, h / 2 - 0.01), "top", "lid_lift")]
    return Draft(
        r,
        {"two_handles": two},
        [],
        cav,
        [colour_name(c), LID, "two side handles" if two else "long handle", "hot when cooking"],
    )


@register("Fan")
def fan(rng):
    r = Part("root")
    stand = rng.random() < 0.5
    pole = u(rng, 0.7, 0.9) if stand else u(rng, 0.1, 0.18)
    br = u(rng, 0.12, 0.2) if stand else u(rng, 0.09, 0.12)
    c = colour(rng, [WHITE, DARK, METAL[1], (0.4, 0.6, 0.9, 1)])
    r.cyl(br, 0.015, (0, 0, 0.015), c, 3000)
    r.cyl(0.015, pole / 2, (0, 0, 0.03 + pole / 2), c, 1500)
    head = r.child("head", (0, 0, 0.03 + pole))
    head.hinge("head_tilt", (1, 0, 0), (-0.4, 0.4), "hinge", 0.0, hold=True)
    head.cyl(0.045, 0.05, (0, 0.02, 0.05), c, 800, axis="y")
    rad = u(rng, 0.12, 0.18)
    rot = head.child("rotor", (0, -0.04, 0.05))
    rot.hinge("rotor_spin", (0, 1, 0), (0, 2 * math.pi), "rotor", 0.0)
    rot.cyl(0.03, 0.015, (0, 0, 0), c, 800, axis="y")
    n = int(rng.integers(3, 6))
    bc = colour(rng, [(0.6, 0.8, 0.95, 0.8), WHITE, DARK])
    for k in range(n):
        a = 2 * math.pi * k / n
        q = axis_angle((0, 1, 0), a)
        rot.box(
            (rad * 0.42, 0.004, 0.035),
            (rad * 0.5 * math.cos(a), -0.01, -rad * 0.5 * math.sin(a)),
            bc,
            900,
            quat=q,
        )
    for k in range(12):
        a = 2 * math.pi * k / 12
        head.box(
            (0.003, 0.003, math.pi * (rad + 0.01) / 12),
            ((rad + 0.01) * math.cos(a), -0.07, 0.05 + (rad + 0.01) * math.sin(a)),
            (0.85, 0.85, 0.85, 1),
            500,
            quat=axis_angle((0, 1, 0), -a),
            collide=False,
        )
    return Draft(
        r,
        {"standing": stand, "blades": n},
        [],
        [],
        [colour_name(c), f"{n} spinning blades", "tilting head", "standing fan" if stand else "desk fan"],
    )


@register("Lamp")
def lamp(rng):
    r = Part("root")
    br = u(rng, 0.08, 0.11)
    c = colour(rng, [DARK, WHITE, METAL[0], (0.2, 0.4, 0.7, 1), (0.8, 0.2, 0.2, 1)])
    r.cyl(br, 0.012, (0, 0, 0.012), c, 6000)
    l1, l2 = u(rng, 0.2, 0.3), u(rng, 0.2, 0.28)
    a1 = r.child("lower_arm", (0, 0, 0.03))
    a1.hinge("lower_arm_joint", (1, 0, 0), (-0.6, 0.6), "arm", 0.0, hold=True)
    a1.capsule(0.009, l1 / 2, (0, 0, l1 / 2), c, 2000)
    a2 = a1.child("upper_arm", (0, 0, l1))
    a2.hinge("upper_arm_joint", (1, 0, 0), (-1.2, 0.6), "arm", 0.0, hold=True)
    a2.capsule(
        0.008,
        l2 / 2,
        (0, -l2 / 2 * math.sin(1.2), l2 / 2 * math.cos(1.2)),
        c,
        2000,
        quat=axis_angle((1, 0, 0), 1.2),
    )
    sh = a2.child("shade", (0, -l2 * math.sin(1.2), l2 * math.cos(1.2)))
    sh.hinge("shade_joint", (1, 0, 0), (-0.8, 0.8), "arm", 0.0, hold=True)
    sh.cyl(0.055, 0.05, (0, 0, -0.04), c, 300)
    sh.sphere(0.03, (0, 0, -0.09), (1.0, 0.95, 0.7, 1), 100, collide=False)
    button(r, "switch", (br * 0.6, 0, 0.028), (0.01, 0.008, 0.004), DARK)
    return Draft(r, {"arms": 2}, [], [], [colour_name(c), "desk lamp", "adjustable jointed arm", "hot bulb"])


@register("Globe")
def globe(rng):
    r = Part("root")
    rad = u(rng, 0.1, 0.16)
    tilt = 0.41
    c = colour(rng, WOOD + [METAL[0], DARK])
    r.cyl(rad * 0.6, 0.012, (0, 0, 0.012), c, 2000)
    stem = rad * 0.4
    r.cyl(0.012, stem / 2, (0, 0, 0.024 + stem / 2), c, 2000)
    cz = 0.024 + stem + rad + 0.01
    ax = (math.sin(tilt), 0, math.cos(tilt))
    R = (
        rad + 0.012
    )  # meridian half-ring from the north to the south pole on the +x side, tilted with the axis
    n = 10
    pts = [
        (R * math.sin(tilt + math.pi * k / n), 0.0, cz + R * math.cos(tilt + math.pi * k / n))
        for k in range(n + 1)
    ]
    for p0, p1 in zip(pts, pts[1:], strict=False):
        r.segment(p0, p1, 0.004, METAL[1], D_METAL)
    r.segment((0, 0, 0.024 + stem), pts[-1], 0.006, METAL[1], D_METAL)
    g = r.child("sphere", (0, 0, cz))
    g.hinge("spin", ax, (0, 2 * math.pi), "spin", 0.0)
    g.sphere(rad, (0, 0, 0), (0.25, 0.5, 0.85, 1), 200)
    for k in range(4):  # continents
        d = (math.cos(k * 1.7), math.sin(k * 1.7), 0.3 * (k - 1.5))
        nrm = math.sqrt(sum(v * v for v in d))
        g.ellipsoid(
            (rad * 0.35, rad * 0.25, rad * 0.1),
            tuple(rad * 0.93 * v / nrm for v in d),
            (0.3, 0.65, 0.3, 1),
            100,
            collide=False,
            quat=axis_angle((-d[1], d[0], 0), math.acos(max(-1, min(1, d[2] / nrm))) + 1e-6)
            if abs(d[0]) + abs(d[1]) > 1e-6
            else (1, 0, 0, 0),
        )
    return Draft(r, {}, [], [], [colour_name(c), "spinning world map sphere on a stand"])


@register("Clock")
def clock(rng):
    r = Part("root")
    rad, depth = u(rng, 0.1, 0.18), u(rng, 0.03, 0.05)
    c = colour(rng, WOOD + [DARK, WHITE, (0.7, 0.2, 0.2, 1)])
    r.box((rad * 0.8, depth * 1.5, 0.015), (0, 0, 0.015), c, 1500)  # foot
    cz = 0.03 + rad
    r.cyl(rad, depth / 2, (0, 0, cz), c, 600, axis="y")
    r.cyl(rad * 0.9, 0.001, (0, -depth / 2 - 0.001, cz), WHITE, 100, axis="y", collide=False)
    for k in range(12):
        a = 2 * math.pi * k / 12
        r.box(
            (0.003, 0.001, 0.01),
            (rad * 0.8 * math.sin(a), -depth / 2 - 0.002, cz + rad * 0.8 * math.cos(a)),
            DARK,
            100,
            quat=axis_angle((0, 1, 0), a),
            collide=False,
        )
    for name, length, wid in (("hour_hand", 0.5, 0.006), ("minute_hand", 0.8, 0.004)):
        hnd = r.child(name, (0, -depth / 2 - 0.004 - (0.002 if name == "minute_hand" else 0), cz))
        hnd.hinge(f"{name}_joint", (0, -1, 0), (0, 2 * math.pi), "hand", 0.0)
        hnd.box((wid, 0.001, rad * length / 2), (0, 0, rad * length / 2), DARK, 2000)
    return Draft(r, {}, [], [], [colour_name(c), "round face", "hour and minute hands"])


@register("Bucket")
def bucket(rng):
    r = Part("root")
    rad, h = u(rng, 0.12, 0.16), u(rng, 0.2, 0.3)
    c = colour(rng, PLASTIC + METAL[:2])
    r.cyl(rad * 0.85, 0.004, (0, 0, 0.004), c, 1200)
    r.ring(rad * 0.92, 0.008, h, 0.005, 16, c, 1200)
    hd = r.child("handle", (0, 0, h * 0.92))
    hd.hinge("handle_hinge", (1, 0, 0), (0, 1.55), "handle", 0.0)
    n = 8
    pts = [
        (rad * math.cos(math.pi * k / n), rad * 0.9 * math.sin(math.pi * k / n), 0.02) for k in range(n + 1)
    ]
    for a, b in zip(pts, pts[1:], strict=False):
        hd.segment(a, b, 0.004, METAL[1], D_METAL)
    cav = [Cavity("inside", (0, 0, h / 2), (rad * 0.65, rad * 0.65, h / 2 - 0.01), "top")]
    return Draft(
        r, {}, [], cav, [colour_name(c), "swing handle", "open top, holds water: a toddler can drown in it"]
    )


@register("Box")
def box(rng):
    r = Part("root")
    hx, hy, hz, t = u(rng, 0.12, 0.25), u(rng, 0.1, 0.2), u(rng, 0.08, 0.18), 0.006
    cardboard = rng.random() < 0.5
    c = (0.72, 0.55, 0.35, 1) if cardboard else colour(rng, PLASTIC + WOOD[:2])
    open_box(r, hx, hy, hz, t, c, 700)
    if cardboard:
        for s, name in ((-1, "flap_front"), (1, "flap_back")):
            f = r.child(name, (0, s * hy, 2 * hz))
            f.hinge(f"{name}_hinge", (1, 0, 0), (-2.2, 0) if s > 0 else (0, 2.2), FLAP, 0.0)
            f.box((hx - 0.002, hy / 2 - 0.002, t / 2), (0, -s * hy / 2, t / 2 + s * 0.0), c, 700)
        joint = "flap_front_hinge"
        feats = ["cardboard", "two top flaps"]
    else:
        top_lid(r, "lid", hx, hy, 2 * hz, c, 700, thick=t)
        joint = "lid_hinge"
        feats = [colour_name(c), "hinged lid"]
    cav = [Cavity("inside", (0, 0, hz + t / 2), (hx - 1.5 * t, hy - 1.5 * t, hz - t), "top", joint)]
    return Draft(
        r,
        {"cardboard": cardboard},
        [Surface("top", (0, 0, 2 * hz + t), (hx - 0.01, hy - 0.01))],
        cav,
        feats + ["storage box, can be closed"],
    )


@register("Suitcase")
def suitcase(rng):
    r = Part("root")
    hx, hy, hz, t = u(rng, 0.18, 0.25), u(rng, 0.1, 0.14), u(rng, 0.25, 0.35), 0.01
    c = colour(rng, FABRIC + PLASTIC[:3] + [DARK])
    open_box(r, hx, hy, hz, t, c, 400, top=True, front=False)
    side_door(r, "lid", -hx, hx, 0.004, 2 * hz - 0.002, -hy + 0.002, True, c, 400, thick=0.05, handle=False)
    r.children[-1].joint.label = LID
    r.children[-1].label = LID
    hd = r.child("handle", (0, hy * 0.6, 2 * hz - 0.1))
    hd.slide("handle_slide", (0, 0, 1), (0, 0.3), "handle", 0.0)
    for s in (-1, 1):
        hd.box((0.008, 0.008, 0.1), (s * hx * 0.5, 0, 0.02), METAL[1], D_METAL)
    hd.box((hx * 0.5 + 0.008, 0.012, 0.012), (0, 0, 0.13), DARK, 1100)
    for s in (-1, 1):
        r.cyl(0.02, 0.01, (s * (hx - 0.03), hy - 0.03, 0.02), DARK, 1200, axis="x")
    cav = [Cavity("inside", (0, 0.02, hz), (hx - 1.5 * t, hy - 0.03 - t, hz - 1.5 * t), "front", "lid_hinge")]
    return Draft(
        r, {}, [], cav, [colour_name(c), "zip-around lid", "telescoping handle", "trip hazard in a hallway"]
    )


@register("Bottle")
def bottle(rng):
    r = Part("root")
    rad, h = u(rng, 0.03, 0.045), u(rng, 0.18, 0.28)
    c = colour(
        rng, [GLASS, (0.2, 0.5, 0.25, 0.7), (0.45, 0.25, 0.1, 0.75), (0.6, 0.8, 0.95, 0.6)] + PLASTIC[:2]
    )
    r.cyl(rad, h * 0.35, (0, 0, h * 0.35), c, 800)
    r.cyl(rad * 0.7, h * 0.06, (0, 0, h * 0.76), c, 800)
    r.cyl(rad * 0.38, h * 0.1, (0, 0, h * 0.9), c, 800)
    cap = r.child("cap", (0, 0, h))
    cap.slide("cap_lift", (0, 0, 1), (0, 0.03), "cap", 0.0)
    cap.cyl(rad * 0.42, 0.01, (0, 0, 0.01), colour(rng, PLASTIC + METAL[:1]), 900)
    return Draft(r, {}, [], [], [colour_name(c), "screw cap", "may hold a drink, oil or chemical"])
