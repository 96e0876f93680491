"""A tiny part tree that generators describe objects in, before anything touches MuJoCo.

Why not write straight into ``MjSpec``: an asset must be uniformly rescaled to a requested size and
re-centred so its bottom sits at z = 0. Both are trivial on a plain tree of primitives (we know every
geom's extent and volume analytically) and awkward after the fact on a spec. The tree also gives the
bounding box and mass without compiling, which keeps catalogue building fast.

Conventions: metres, radians, quaternions (w, x, y, z). Cylinders and capsules run along their local
z axis; ``axis="x"|"y"`` rotates them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import partialmethod

import numpy as np

_AXIS_QUAT = {
    "z": (1.0, 0.0, 0.0, 0.0),
    "x": (math.cos(math.pi / 4), 0.0, math.sin(math.pi / 4), 0.0),
    "y": (math.cos(math.pi / 4), -math.sin(math.pi / 4), 0.0, 0.0),
}


def quat_mul(a, b) -> tuple[float, float, float, float]:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return (
        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
    )


def axis_angle(axis, angle: float) -> tuple[float, float, float, float]:
    ax = np.asarray(axis, dtype=float)
    ax = ax / np.linalg.norm(ax)
    s = math.sin(angle / 2)
    return (math.cos(angle / 2), float(ax[0] * s), float(ax[1] * s), float(ax[2] * s))


def quat_to_mat(q) -> np.ndarray:
    w, x, y, z = q
    n = math.sqrt(w * w + x * x + y * y + z * z) or 1.0
    w, x, y, z = w / n, x / n, y / n, z / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


@dataclass
class Geom:
    kind: str  # box | cylinder | capsule | sphere | ellipsoid
    size: tuple[float, ...]  # MuJoCo half-size convention
    pos: tuple[float, float, float]
    quat: tuple[float, float, float, float]
    rgba: tuple[float, float, float, float]
    density: float
    collide: bool = True
    name: str | None = None

    def half_extents(self) -> np.ndarray:
        s = self.size
        if self.kind in ("box", "ellipsoid"):
            local = (s[0], s[1], s[2])
        elif self.kind == "sphere":
            local = (s[0], s[0], s[0])
        elif self.kind == "cylinder":
            local = (s[0], s[0], s[1])
        else:  # capsule
            local = (s[0], s[0], s[1] + s[0])
        return np.abs(quat_to_mat(self.quat)) @ np.asarray(local)

    @property
    def mass_density(self) -> float:
        """Decorative (non-colliding) geoms are massless: a label or a mould spot must not shift the
        centre of mass and make an object roll."""
        return self.density if self.collide else 0.0

    def volume(self) -> float:
        s = self.size
        if self.kind == "box":
            return 8 * s[0] * s[1] * s[2]
        if self.kind == "sphere":
            return 4 / 3 * math.pi * s[0] ** 3
        if self.kind == "cylinder":
            return math.pi * s[0] ** 2 * 2 * s[1]
        if self.kind == "capsule":
            return math.pi * s[0] ** 2 * 2 * s[1] + 4 / 3 * math.pi * s[0] ** 3
        return 4 / 3 * math.pi * s[0] * s[1] * s[2]


@dataclass
class JointDef:
    name: str
    type: str  # hinge | slide
    axis: tuple[float, float, float]
    range: tuple[float, float]
    label: str
    closed: float
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    spring: bool = False  # a preloaded spring returns it to closed (buttons, pedals, levers)
    hold: bool = False  # friction holds any pose against gravity (lamp arms, screen tilt)


@dataclass
class Part:
    """A body: primitives, at most one joint to its parent, and child parts."""

    name: str
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    geoms: list[Geom] = field(default_factory=list)
    joint: JointDef | None = None
    children: list[Part] = field(default_factory=list)
    label: str = ""

    # ------------------------------------------------------------------ geometry helpers
    def _add(self, kind, size, pos, quat, rgba, density, collide, name) -> Geom:
        g = Geom(
            kind,
            tuple(float(v) for v in size),
            tuple(float(v) for v in pos),
            tuple(quat),
            tuple(rgba),
            float(density),
            collide,
            name,
        )
        self.geoms.append(g)
        return g

    def _geom(
        self,
        kind,
        size,
        pos=(0, 0, 0),
        rgba=(0.7, 0.7, 0.7, 1),
        density=700.0,
        *,
        axis="z",
        quat=None,
        collide=True,
        name=None,
    ):
        """One primitive; ``quat`` (w, x, y, z) wins over ``axis``, the direction a cylinder or capsule runs along."""
        return self._add(kind, size, pos, quat or _AXIS_QUAT[axis], rgba, density, collide, name)

    # box(half, pos, rgba, density, *, quat, collide, name); an ellipsoid takes the same arguments
    box = partialmethod(_geom, "box", quat=(1, 0, 0, 0))
    ellipsoid = partialmethod(_geom, "ellipsoid", quat=(1, 0, 0, 0))

    def cyl(self, r, hh, *args, **kwargs):
        """A cylinder of radius ``r`` and half height ``hh``; then pos, rgba, density, *, axis, quat, collide, name."""
        return self._geom("cylinder", (r, hh), *args, **kwargs)

    def capsule(self, r, hh, *args, **kwargs):
        """A capsule, with the arguments of ``cyl``."""
        return self._geom("capsule", (r, hh), *args, **kwargs)

    def sphere(self, r, pos=(0, 0, 0), rgba=(0.7, 0.7, 0.7, 1), density=700.0, *, collide=True, name=None):
        return self._add("sphere", (r,), pos, (1, 0, 0, 0), rgba, density, collide, name)

    def segment(self, a, b, r, rgba=(0.7, 0.7, 0.7, 1), density=700.0, *, kind="capsule", collide=True):
        """A capsule/cylinder from point a to point b (for legs, handles, cable links)."""
        a, b = np.asarray(a, float), np.asarray(b, float)
        d = b - a
        length = float(np.linalg.norm(d))
        z = np.array([0.0, 0.0, 1.0])
        axis = np.cross(z, d)
        if np.linalg.norm(axis) < 1e-9:
            quat = (1.0, 0.0, 0.0, 0.0) if d[2] >= 0 else (0.0, 1.0, 0.0, 0.0)
        else:
            quat = axis_angle(axis, math.acos(max(-1.0, min(1.0, d[2] / length))))
        return self._add(kind, (r, length / 2), (a + b) / 2, quat, rgba, density, collide, None)

    def ring(
        self, r, z0, z1, thick, n=12, rgba=(0.7, 0.7, 0.7, 1), density=700.0, center=(0.0, 0.0), ry=None
    ):
        """A thin cylindrical (or elliptical) wall of n boxes: hollow containers that can hold things."""
        ry = ry or r
        hz = (z1 - z0) / 2
        for i in range(n):
            a = 2 * math.pi * i / n
            x, y = center[0] + r * math.cos(a), center[1] + ry * math.sin(a)
            seg = math.pi * (r + ry) / n * 1.08
            self.box((thick / 2, seg / 2, hz), (x, y, z0 + hz), rgba, density, quat=axis_angle((0, 0, 1), a))

    def child(self, name, pos=(0, 0, 0), quat=(1, 0, 0, 0), label="") -> Part:
        p = Part(name, tuple(float(v) for v in pos), tuple(quat), label=label)
        self.children.append(p)
        return p

    def hinge(
        self, name, axis, range, label, closed=None, pos=(0, 0, 0), *, spring=False, hold=False
    ) -> JointDef:
        return self._joint("hinge", name, axis, range, label, closed, pos, spring, hold)

    def slide(
        self, name, axis, range, label, closed=None, pos=(0, 0, 0), *, spring=False, hold=False
    ) -> JointDef:
        return self._joint("slide", name, axis, range, label, closed, pos, spring, hold)

    def _joint(self, kind, name, axis, range, label, closed, pos, spring, hold) -> JointDef:
        """The one joint of this part; closed defaults to the range's lower end."""
        self.joint = JointDef(
            name,
            kind,
            tuple(axis),
            (float(range[0]), float(range[1])),
            label,
            float(range[0] if closed is None else closed),
            tuple(pos),
            spring,
            hold,
        )
        self.label = self.label or label
        return self.joint

    # ------------------------------------------------------------------ analytic queries
    def walk(self, pos=np.zeros(3), rot=np.eye(3)):
        """Yield (part, world_pos, world_rot) with joints at zero."""
        yield self, pos, rot
        for c in self.children:
            cpos = pos + rot @ np.asarray(c.pos)
            crot = rot @ quat_to_mat(c.quat)
            yield from c.walk(cpos, crot)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
        for part, pos, rot in self.walk():
            for g in part.geoms:
                c = pos + rot @ np.asarray(g.pos)
                h = np.abs(rot) @ g.half_extents()
                lo, hi = np.minimum(lo, c - h), np.maximum(hi, c + h)
        return lo, hi

    def mass(self) -> float:
        return sum(g.volume() * g.mass_density for p, _, _ in self.walk() for g in p.geoms)

    def subtree_inertia(self, about: np.ndarray) -> float:
        """Rough moment of inertia of this subtree about a point (for joint damping/armature)."""
        total = 0.0
        for part, pos, rot in self.walk():
            for g in part.geoms:
                m = g.volume() * g.mass_density
                c = pos + rot @ np.asarray(g.pos)
                total += m * (float(np.sum((c - about) ** 2)) + float(np.sum(g.half_extents() ** 2)) / 3)
        return total

    def com(self) -> np.ndarray:
        """Centre of mass of this subtree in this part's frame (joints at zero)."""
        m, acc = 0.0, np.zeros(3)
        for part, pos, rot in self.walk():
            for g in part.geoms:
                gm = g.volume() * g.mass_density
                m += gm
                acc += gm * (pos + rot @ np.asarray(g.pos))
        return acc / max(m, 1e-12)
