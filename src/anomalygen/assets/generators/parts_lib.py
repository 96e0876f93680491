"""Articulated building blocks shared by the target generators: doors, drawers, knobs, lids.

Every asset faces -y (its front). Each joint's closed value sits at one end of its range, on the side
gravity pushes towards, so a part left alone rests closed against its limit instead of drifting.
Doors and drawers are children of the body they close; MuJoCo already ignores parent-child contacts,
and ``core.finalize`` excludes contacts between an asset's own moving parts, so parts never lock up on
their own cabinet.
"""

from __future__ import annotations

from anomalygen.assets.generators.common import D_METAL, METAL, open_box
from anomalygen.assets.model import Cavity
from anomalygen.assets.parts import Part
from anomalygen.schema import DOOR, DRAWER, KNOB, LID, SWITCH, TAP


def side_door(
    parent: Part,
    name: str,
    x0,
    x1,
    z0,
    z1,
    y,
    hinge_left: bool,
    rgba,
    density,
    thick=0.018,
    handle=True,
    open_angle=1.9,
):
    """A door on a vertical hinge covering x0..x1, z0..z1, its back face at y (the cabinet front)."""
    w, hz, zc = x1 - x0, (z1 - z0) / 2, (z0 + z1) / 2
    if hinge_left:
        d = parent.child(name, (x0, y - 0.002, zc))
        d.hinge(f"{name}_hinge", (0, 0, 1), (-open_angle, 0), DOOR, 0.0)
        sx = 1
    else:
        d = parent.child(name, (x1, y - 0.002, zc))
        d.hinge(f"{name}_hinge", (0, 0, 1), (0, open_angle), DOOR, 0.0)
        sx = -1
    d.box((w / 2 - 0.002, thick / 2, hz - 0.002), (sx * w / 2, -thick / 2, 0), rgba, density)
    if handle:
        hl = min(0.12, hz * 0.6)
        d.box((0.008, 0.012, hl / 2), (sx * (w - 0.04), -thick - 0.012, 0), METAL[0], D_METAL)
    return d


def drop_door(
    parent: Part, name: str, x0, x1, z0, z1, y, rgba, density, thick=0.03, handle=True, window=None
):
    """A door hinged along its bottom edge that falls open forward (oven, dishwasher)."""
    w, h = x1 - x0, z1 - z0
    d = parent.child(name, ((x0 + x1) / 2, y - 0.002, z0))
    d.hinge(f"{name}_hinge", (1, 0, 0), (0, 1.55), DOOR, 0.0)
    d.box((w / 2 - 0.002, thick / 2, h / 2 - 0.002), (0, -thick / 2, h / 2), rgba, density)
    if window is not None:
        d.box((w * 0.35, 0.001, h * 0.25), (0, -thick - 0.001, h * 0.5), window, 100, collide=False)
    if handle:
        d.segment(
            (-w * 0.35, -thick - 0.025, h * 0.88),
            (w * 0.35, -thick - 0.025, h * 0.88),
            0.008,
            METAL[0],
            D_METAL,
        )
        for sx in (-1, 1):
            d.segment(
                (sx * w * 0.33, -thick, h * 0.88),
                (sx * w * 0.33, -thick - 0.025, h * 0.88),
                0.006,
                METAL[0],
                D_METAL,
            )
    return d


def drawer(parent: Part, name: str, x0, x1, z0, z1, y, depth, rgba, density, t=0.012):
    """A drawer front plus an open bin behind it, sliding out along -y; returns (part, bin cavity)."""
    w, h = x1 - x0, z1 - z0
    dr = parent.child(name, ((x0 + x1) / 2, y - 0.002, z0))
    travel = depth * 0.8
    dr.slide(f"{name}_slide", (0, -1, 0), (0, travel), DRAWER, 0.0)
    dr.box((w / 2 - 0.002, 0.009, h / 2 - 0.002), (0, -0.009, h / 2), rgba, density)
    dr.box((min(0.06, w * 0.25), 0.01, 0.008), (0, -0.03, h * 0.6), METAL[0], D_METAL)
    bh = h / 2 * 0.75
    open_box(
        dr, w / 2 - 0.02, depth / 2 - 0.01, bh, t, rgba, density, z0=0.012, center=(0, depth / 2 + 0.005)
    )
    cav = Cavity(
        f"{name}_bin",
        (0, 0, 0),
        (w / 2 - 0.02 - t * 1.5, depth / 2 - 0.01 - t * 1.5, bh - t),
        "top",
        f"{name}_slide",
    )
    # cavity centre in the parent frame (closed state)
    cav = Cavity(
        cav.name,
        ((x0 + x1) / 2, y - 0.002 + depth / 2 + 0.005, z0 + 0.012 + bh + t / 2),
        cav.half_extents,
        "top",
        cav.joint,
    )
    return dr, cav


def knob(parent: Part, name: str, pos, r, rgba, axis=(0, -1, 0), label=KNOB, rng_max=4.7):
    """A round knob turning about its own axis (front-facing by default)."""
    k = parent.child(name, pos)
    k.hinge(f"{name}_joint", axis, (0, rng_max), label, 0.0)
    ax = "y" if abs(axis[1]) > 0.5 else "x" if abs(axis[0]) > 0.5 else "z"
    off = [0.0, 0.0, 0.0]
    off["xyz".index(ax)] = r * 0.6 * (1 if sum(axis) > 0 else -1)
    k.cyl(r, r * 0.6, off, rgba, 900, axis=ax)
    k.box(
        (r * 0.15, r * 0.3, r * 0.8) if ax == "y" else (r * 0.8, r * 0.15, r * 0.3),
        [2 * o for o in off],
        (0.9, 0.9, 0.9, 1),
        900,
        collide=False,
    )
    return k


def top_lid(parent: Part, name: str, hx, hy, z, rgba, density, thick=0.01, open_angle=1.9, label=LID):
    """A flat lid hinged along the back (+y) edge at height z, opening upwards."""
    lid = parent.child(name, (0, hy, z))
    lid.hinge(f"{name}_hinge", (1, 0, 0), (-open_angle, 0), label, 0.0)
    lid.box((hx, hy, thick / 2), (0, -hy, thick / 2), rgba, density)
    return lid


# A geom named ``<control body>_glow`` is drawn only while that control is on (a burner's flame, a
# heater's element, a candle's flame); the scene builder shows it (``world/states.py``). Its rgba
# here has alpha 0, so the asset on its own, and a scene with the control off, show nothing.
GLOW = (1.0, 0.35, 0.05, 0.0)


def glow(parent: Part, control: str, kind: str, size, pos, *, quat=None) -> None:
    """A hidden, massless, non-colliding glow for the control body named ``control``."""
    parent._geom(kind, size, pos, GLOW, 0.0, quat=quat, collide=False, name=f"{control}_glow")


PUSH_SWITCH_TRAVEL = 0.006  # m a push switch stands proud when on


def push_switch(parent: Part, name: str, pos, half, rgba, travel: float = PUSH_SWITCH_TRAVEL):
    """A latching on/off push switch on a top face (label "switch"): off pressed down at 0 (its box
    centred at ``pos``), on standing ``travel`` proud. Joint friction is the latch, so a switch left on
    stays on; pressing it down from above puts it off, which is how a suction cup meets a top face
    (the switch-off family's buttons, ``skills/part_motion.py``)."""
    s = parent.child(name, pos)
    s.slide(f"{name}_press", (0, 0, 1), (0, travel), SWITCH, 0.0, hold=True)
    s.box(half, (0, 0, 0), rgba, D_METAL)  # as heavy as its latch: a 3 g cap rang against the cup's hold
    return s


def tap_lever(parent: Part, name: str, pos, length: float, rgba, lift: float = 0.6):
    """A single-lever tap handle on a horizontal hinge (x), pointing to the front (-y): off rests
    down on its limit (gravity keeps it there), on is lifted up to ``lift`` rad. Label "tap"."""
    lv = parent.child(name, pos)
    lv.hinge(f"{name}_hinge", (1, 0, 0), (-lift, 0), TAP, 0.0)
    lv.box((0.008, length / 2, 0.006), (0, -length / 2, 0.006), rgba, D_METAL)
    lv.cyl(0.014, 0.012, (0, 0, 0.0), rgba, D_METAL)
    return lv
