"""The room's structure: the two walls the scene cameras look at, with openings for what is mounted in them.

Why: scenes used to show a patch of floor with walls far behind and the renderer's empty background at
the sides, and windows and doors stood free on the floor in the middle of the room. The walls stand
at ``WALL_X`` (the back wall, facing -x) and ``WALL_Y`` (the side wall, facing -y), the sides the
front camera looks at from the room's open corner; they run far enough to fill every camera's
background. A window or door is mounted in one of them (``layout.Layout.place_on_wall``) and the wall
gets an opening behind it, with a backdrop (sky, hallway) seen through it.

Walls are structure, like the floor: world geoms named ``wall/...``, never objects of the scene spec,
so the scene graph, the detectors and the referee never list them as items.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

WALL_X = 3.2  # m: the back wall's inner face (x): where the layout's floor area ended before walls (ROOM_CENTER + ROOM_HALF + 0.3)
WALL_Y = 2.3  # m: the side wall's inner face (y): likewise, so every layout drawn before walls still fits
WALL_THICK = 0.12  # m
WALL_MIN_HEIGHT = 2.6  # m: a room's height; taller when a camera sits higher (the background stays wall)
WALL_REACH = 12.0  # m: how far the walls run away from the corner (past every camera's view)
WALL_PREFIX = "wall/"  # geom names of the structure (never an object of the scene)
WINDOW_SILL = 0.82  # m: height of a window's sill above the floor (real sills: 0.8-0.9 m)
WALL_MOUNTED = {"Window": WINDOW_SILL, "Door": 0.0}  # category -> height of its bottom above the floor
WALL_GAP = 0.005  # m between a mounted object's back and the wall's face
BACKDROP_DEPTH = 0.6  # m behind the wall: what is seen through an opening
BACKDROP_WIDE = 3.0  # m the backdrop runs past each side of its opening (a view through it at a slant)
GROUND_RGBA = (0.42, 0.5, 0.36, 1.0)  # the ground outside, between the wall and the backdrop
WALL_RGBA = (0.84, 0.82, 0.74, 1.0)
WALL_EMISSION = 0.35  # the lights fall on the walls at a grazing angle: without it they render dark grey
SKIRTING_RGBA = (0.35, 0.27, 0.2, 1.0)
SKIRTING_HEIGHT = 0.08  # m
BACKDROP_RGBA = {"Window": (0.62, 0.78, 0.92, 1.0), "Door": (0.55, 0.5, 0.45, 1.0)}


@dataclass(frozen=True)
class Opening:
    """A hole in a wall: ``wall`` is "back" (x = WALL_X) or "side" (y = WALL_Y); ``along`` is the
    interval along the wall (y for the back wall, x for the side wall), ``z`` the interval in height."""

    wall: str
    along: tuple[float, float]
    z: tuple[float, float]
    kind: str


def is_structure(geom_name: str | None) -> bool:
    return bool(geom_name) and geom_name.startswith(WALL_PREFIX)


def wall_geoms(model, spec=None) -> np.ndarray:
    """Ids of the walls' geoms, and (given the scene spec) of the objects mounted in them: what the
    background of a render should be made of."""
    from anomalygen.robot.frames import subtree_geoms

    mask = np.array([is_structure(model.geom(g).name) for g in range(model.ngeom)], dtype=bool)
    for o in spec.objects if spec is not None else ():
        if mount_height(o.asset.category) is not None:
            mask |= subtree_geoms(model, model.body(o.name).id)
    return np.flatnonzero(mask)


def mount_height(category: str) -> float | None:
    """Height of the bottom of a wall-mounted category (None: it is not mounted in a wall)."""
    return WALL_MOUNTED.get(category)


def opening_for(wall: str, lo: np.ndarray, hi: np.ndarray, kind: str) -> Opening:
    """The opening behind a mounted object whose world AABB is (lo, hi)."""
    axis = 1 if wall == "back" else 0
    return Opening(wall, (float(lo[axis]), float(hi[axis])), (max(float(lo[2]), 0.0), float(hi[2])), kind)


def wall_of(lo: np.ndarray, hi: np.ndarray, tol: float = 0.05) -> str | None:
    """The wall a world AABB stands against ("back"/"side"), or None."""
    if abs(float(hi[0]) - WALL_X) <= tol:
        return "back"
    if abs(float(hi[1]) - WALL_Y) <= tol:
        return "side"
    return None


def emit_walls(spec, openings: list[Opening], height: float) -> None:
    """Add the two walls (with their openings, skirting and backdrops) to an MjSpec's world body."""
    import mujoco

    tex = spec.add_texture(name="wall_tex", type=mujoco.mjtTexture.mjTEXTURE_2D,
                           builtin=mujoco.mjtBuiltin.mjBUILTIN_FLAT, mark=mujoco.mjtMark.mjMARK_RANDOM,
                           random=0.02, rgb1=list(WALL_RGBA[:3]), rgb2=list(WALL_RGBA[:3]),
                           markrgb=[0.78, 0.76, 0.68], width=128, height=128)
    mat = spec.add_material(name="wall_mat", texrepeat=[4, 4], reflectance=0.0, emission=WALL_EMISSION)
    mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = tex.name
    height = max(height, WALL_MIN_HEIGHT)
    for wall in ("back", "side"):
        holes = sorted((o for o in openings if o.wall == wall), key=lambda o: o.along[0])
        start = (WALL_Y if wall == "back" else WALL_X) - WALL_REACH
        end = (WALL_Y if wall == "back" else WALL_X) + WALL_THICK  # the corner: the back wall covers it
        for i, (a0, a1, z0, z1) in enumerate(_pieces(start, end, holes, height)):
            _box(spec, wall, f"{WALL_PREFIX}{wall}_{i}", (a0, a1), (z0, z1), material="wall_mat")
        doors = [o for o in holes if o.z[0] <= 1e-3]
        for k, (a0, a1, _, _) in enumerate(_pieces(start, end - WALL_THICK, doors, SKIRTING_HEIGHT)):
            if a1 - a0 > 1e-3 and not any(o.along[0] <= a0 and a1 <= o.along[1] for o in doors):
                _box(spec, wall, f"{WALL_PREFIX}{wall}_skirting_{k}", (a0, a1), (0.0, SKIRTING_HEIGHT),
                     rgba=SKIRTING_RGBA, inset=-0.01, collide=False)
        for j, o in enumerate(holes):  # what is seen through an opening: a backdrop, and ground before it
            wide = (o.along[0] - BACKDROP_WIDE, o.along[1] + BACKDROP_WIDE)
            _box(spec, wall, f"{WALL_PREFIX}{wall}_backdrop_{j}", wide, (0.0, height),
                 rgba=BACKDROP_RGBA.get(o.kind, WALL_RGBA), inset=WALL_THICK + BACKDROP_DEPTH, collide=False)
            _box(spec, wall, f"{WALL_PREFIX}{wall}_ground_{j}", wide, (-0.02, 0.0), rgba=GROUND_RGBA,
                 inset=0.0, depth=(WALL_THICK + BACKDROP_DEPTH) / 2, collide=False)


def _pieces(start: float, end: float, holes: list[Opening], height: float):
    """Boxes (along0, along1, z0, z1) that make a wall from ``start`` to ``end`` with ``holes``."""
    out, at = [], start
    for o in holes:
        a0, a1 = max(o.along[0], at), min(o.along[1], end)
        if a1 <= a0:
            continue
        out.append((at, a0, 0.0, height))
        if o.z[0] > 1e-3:
            out.append((a0, a1, 0.0, o.z[0]))
        out.append((a0, a1, o.z[1], height))
        at = a1
    out.append((at, end, 0.0, height))
    return [p for p in out if p[1] - p[0] > 1e-3 and p[3] - p[2] > 1e-3]


def _box(spec, wall: str, name: str, along, z, *, material=None, rgba=None, inset: float = 0.0,
         depth: float | None = None, collide: bool = True) -> None:
    """A box of the wall: ``along`` and ``z`` intervals, its inner face ``inset`` behind the wall's
    face, ``depth`` its half-thickness (default: the wall's; 1 cm for a skirting board before it)."""
    import mujoco

    half_a, half_z = (along[1] - along[0]) / 2, (z[1] - z[0]) / 2
    mid_a, mid_z = (along[0] + along[1]) / 2, (z[0] + z[1]) / 2
    if depth is None:
        depth = WALL_THICK / 2 if inset >= 0 else 0.01
    face = inset + depth
    if wall == "back":
        pos, size = [WALL_X + face, mid_a, mid_z], [depth, half_a, half_z]
    else:
        pos, size = [mid_a, WALL_Y + face, mid_z], [half_a, depth, half_z]
    geom = spec.worldbody.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_BOX, size=size, pos=pos)
    if material is not None:
        geom.material = material
    if rgba is not None:
        geom.rgba = list(rgba)
    if not collide:
        geom.contype = 0
        geom.conaffinity = 0
