"""The Asset interface every stage consumes, and the step that turns a generator's draft into one.

An Asset is a standalone ``mujoco.MjSpec`` (compiler in radians) whose worldbody holds exactly one body
named ``root`` with no free joint, plus the facts other stages need without compiling anything:
bounding box (bottom at z = 0, centred in x/y), mass, labelled joints with their safe values, support
surfaces and cavities, and a retrieval description. The scene builder decides whether root gets a
free joint (loose objects) or stays welded (furniture).
"""

from __future__ import annotations

import functools
import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from importlib import resources
from typing import Any

import numpy as np

from anomalygen.assets.parts import Part
from anomalygen.schema import AssetRef, AssetSource


@dataclass(frozen=True)
class AssetJoint:
    name: str  # unprefixed joint name in the asset spec
    type: str  # hinge | slide
    range: tuple[float, float]  # radians or metres
    label: str  # door, drawer, lid, knob, handle, button, blade, wheel, rotor, seat, pedal, sash, ...
    closed_value: float  # the safe / closed state
    axis: tuple[float, float, float]
    body: str = ""  # unprefixed name of the moving body


@dataclass(frozen=True)
class Surface:
    """A place things can rest on: top height ``center[2]``, rectangle half sizes in x, y."""

    name: str
    center: tuple[float, float, float]
    half_size: tuple[float, float]


@dataclass(frozen=True)
class Cavity:
    """An interior that can hold objects; ``joint`` closes it (None when always open)."""

    name: str
    center: tuple[float, float, float]
    half_extents: tuple[float, float, float]
    opening: str  # top | front
    joint: str | None = None


@dataclass
class Draft:
    """What a generator returns: geometry at a nominal size plus the semantic extras."""

    root: Part
    params: dict[str, Any] = field(default_factory=dict)
    surfaces: list[Surface] = field(default_factory=list)
    cavities: list[Cavity] = field(default_factory=list)
    features: list[str] = field(default_factory=list)  # words for the description: "two doors", "red"


@dataclass
class Asset:
    asset_id: str
    name: str
    category: str
    source: AssetSource
    seed: int | None
    spec: Any  # mujoco.MjSpec
    aabb: tuple[np.ndarray, np.ndarray]
    mass: float
    joints: list[AssetJoint]
    surfaces: list[Surface]
    cavities: list[Cavity]
    description: str
    params: dict[str, Any] = field(default_factory=dict)
    path: str | None = None
    features: list[str] = field(default_factory=list)  # the generator's words for this variant
    _keep: list = field(default_factory=list, repr=False)

    @property
    def size(self) -> float:
        """Largest dimension in metres."""
        return float(np.max(self.aabb[1] - self.aabb[0]))

    @property
    def ref(self) -> AssetRef:
        return AssetRef(
            asset_id=self.asset_id,
            category=self.category,
            source=self.source,
            seed=self.seed,
            params=dict(self.params),
            path=self.path,
        )

    def root_body(self):
        return self.spec.worldbody.first_body()

    def attach(self, parent, prefix: str):
        """Attach a copy of this asset under ``parent`` (an MjsBody or MjsFrame); names get ``prefix``."""
        import mujoco

        frame = parent.add_frame() if isinstance(parent, mujoco.MjsBody) else parent
        # Attach a fresh copy: MuJoCo attaches by reference, and this spec must stay reusable
        # (attached many times, compiled on its own). Keep the copy alive as long as the asset.
        copy = self.spec.copy()
        self._keep.append(copy)
        return frame.attach_body(copy.worldbody.first_body(), prefix, "")

    def joint(self, name: str) -> AssetJoint:
        for j in self.joints:
            if j.name == name:
                return j
        raise KeyError(name)


# ----------------------------------------------------------------------------- per-name facts


@functools.cache
def object_table() -> dict[str, tuple[float, float, str, tuple[str, ...]]]:
    raw = json.loads(resources.files("anomalygen.data").joinpath("assets/objects.json").read_text())[
        "objects"
    ]
    return {k: (float(v[0]), float(v[1]), v[2], tuple(v[3].split())) for k, v in raw.items()}


@functools.cache
def vocabulary() -> dict[str, Any]:
    return json.loads(resources.files("anomalygen.data").joinpath("vocabulary.json").read_text())


def target_names() -> list[str]:
    return list(vocabulary()["targets"])


def household_names() -> list[str]:
    return list(vocabulary()["household"])


@functools.cache
def _knowledge_sizes() -> dict[str, tuple[float, float]]:
    """``size_range`` of every object in the knowledge base, the project's single source of sizes."""
    try:
        raw = json.loads(resources.files("anomalygen.data").joinpath("knowledge/objects.json").read_text())
    except (FileNotFoundError, json.JSONDecodeError):
        return {}
    objs = raw.get("objects", {})
    items = objs.items() if isinstance(objs, dict) else ((o.get("name"), o) for o in objs)
    out = {}
    for name, info in items:
        sr = info.get("size_range") if isinstance(info, dict) else None
        if name and sr and len(sr) == 2 and 0 < sr[0] <= sr[1]:
            out[name] = (float(sr[0]), float(sr[1]))
    return out


def size_range(name: str) -> tuple[float, float]:
    """Plausible largest dimension (metres) for a vocabulary name: the knowledge base's
    ``ObjectInfo.size_range`` when it has one, else the asset table's."""
    if name in _knowledge_sizes():
        return _knowledge_sizes()[name]
    try:
        lo, hi, _, _ = object_table()[name]
    except KeyError:
        raise KeyError(f"unknown asset name {name!r}") from None
    return lo, hi


def tags(name: str) -> tuple[str, ...]:
    return object_table()[name][3]


def group(name: str) -> str:
    return object_table()[name][2]


# ----------------------------------------------------------------------------- draft -> Asset


def _joint_gains(part: Part, scale: float) -> tuple[float, float]:
    """Damping and armature proportional to the moving subtree's inertia, so small caps and heavy
    fridge doors both settle in a fraction of a second instead of ringing or freezing."""
    j = part.joint
    if j.type == "slide":
        eff = part.mass() * scale**3
    else:
        eff = part.subtree_inertia(np.asarray(j.pos)) * scale**5
    return max(2.0 * eff, 1e-5), max(0.2 * eff, 1e-6)


_GEOM_TYPES = {
    "box": "mjGEOM_BOX",
    "sphere": "mjGEOM_SPHERE",
    "cylinder": "mjGEOM_CYLINDER",
    "capsule": "mjGEOM_CAPSULE",
    "ellipsoid": "mjGEOM_ELLIPSOID",
}


def _emit(mujoco, part: Part, body, scale: float, offset: np.ndarray, joints: list[AssetJoint]) -> None:
    for g in part.geoms:
        size = [v * scale for v in g.size] + [0.0] * (3 - len(g.size))
        geom = body.add_geom(
            type=getattr(mujoco.mjtGeom, _GEOM_TYPES[g.kind]),
            size=size,
            pos=list(np.asarray(g.pos) * scale + offset),
            quat=list(g.quat),
            rgba=list(g.rgba),
            density=g.mass_density,
        )
        if g.name:
            geom.name = g.name
        if not g.collide:
            geom.contype = 0
            geom.conaffinity = 0
            geom.group = 1
    if part.joint is not None:
        j = part.joint
        rng = j.range if j.type == "hinge" else (j.range[0] * scale, j.range[1] * scale)
        closed = j.closed if j.type == "hinge" else j.closed * scale
        damping, armature = _joint_gains(part, scale)
        extra = {}
        if j.spring or j.hold:
            # Worst-case gravity load on this joint: weight times lever arm (or weight for slides).
            m = part.mass() * scale**3
            lever = (
                1.0
                if j.type == "slide"
                else float(
                    np.linalg.norm(
                        np.cross(np.asarray(j.axis, float), (part.com() - np.asarray(j.pos)) * scale)
                    )
                )
            )
            load = m * 9.81 * lever + 1e-6
            if j.hold:
                extra["frictionloss"] = 1.5 * load
            if j.spring:
                span = abs(rng[1] - rng[0])
                far = rng[1] if abs(rng[1] - closed) >= abs(rng[0] - closed) else rng[0]
                extra["stiffness"] = 3.0 * load / span
                extra["springref"] = closed - (far - closed)
        joint = body.add_joint(
            name=j.name,
            type=mujoco.mjtJoint.mjJNT_HINGE if j.type == "hinge" else mujoco.mjtJoint.mjJNT_SLIDE,
            axis=list(j.axis),
            pos=list(np.asarray(j.pos) * scale),
            range=list(rng),
            damping=damping,
            armature=armature,
            ref=0.0,
        )
        if "frictionloss" in extra:
            joint.frictionloss = extra["frictionloss"]
        if "stiffness" in extra:
            cur = joint.stiffness
            joint.stiffness = (
                [extra["stiffness"]] + [0.0] * (len(cur) - 1)
                if hasattr(cur, "__len__")
                else extra["stiffness"]
            )
            joint.springref = extra["springref"]
        joints.append(
            AssetJoint(
                j.name,
                j.type,
                (float(rng[0]), float(rng[1])),
                j.label,
                float(closed),
                tuple(float(a) for a in j.axis),
                part.name,
            )
        )
    for c in part.children:
        cb = body.add_body(name=c.name, pos=list(np.asarray(c.pos) * scale + offset), quat=list(c.quat))
        _emit(mujoco, c, cb, scale, np.zeros(3), joints)


def _exclude_self_contacts(spec, root: Part) -> None:
    """No contacts between an asset's own bodies: a door must swing past its neighbours, a seat
    through its lid's space. Parent-child pairs need excluding too: MuJoCo's parent filter does not
    apply once furniture is welded to the world, and then a door would jam on its own cabinet."""
    names = [p.name for p, _, _ in root.walk()]
    names[0] = "root"
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            ex = spec.add_exclude()
            ex.bodyname1, ex.bodyname2 = a, b


def new_spec():
    import mujoco

    spec = mujoco.MjSpec()
    spec.compiler.degree = False
    spec.compiler.autolimits = True
    return spec


def finalize(
    draft: Draft,
    *,
    name: str,
    seed: int | None,
    size: float | None,
    rng: np.random.Generator,
    source=AssetSource.PROCEDURAL,
) -> Asset:
    """Scale the draft to the requested (clamped) largest dimension, centre it, emit the MjSpec."""
    import mujoco

    from anomalygen.assets.describe import describe

    lo, hi = draft.root.bounds()
    nominal = float(np.max(hi - lo))
    smin, smax = size_range(name)
    # Generators draw realistic nominal sizes, so the default keeps them (scale 1: a counter stays
    # counter-height); an explicit size rescales uniformly within the plausible range.
    target = float(np.clip(nominal if size is None else size, smin, smax))
    scale = target / nominal
    offset = -np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]]) * scale

    spec = new_spec()
    root = spec.worldbody.add_body(name="root")
    joints: list[AssetJoint] = []
    _emit(mujoco, draft.root, root, scale, offset, joints)
    _exclude_self_contacts(spec, draft.root)

    def tf(p):
        return tuple(float(v) for v in np.asarray(p) * scale + offset)

    surfaces = [
        Surface(s.name, tf(s.center), (s.half_size[0] * scale, s.half_size[1] * scale))
        for s in draft.surfaces
    ]
    cavities = [
        Cavity(c.name, tf(c.center), tuple(h * scale for h in c.half_extents), c.opening, c.joint)
        for c in draft.cavities
    ]
    ext = (hi - lo) * scale
    aabb = (np.array([-ext[0] / 2, -ext[1] / 2, 0.0]), np.array([ext[0] / 2, ext[1] / 2, ext[2]]))
    params = {"size": round(target, 5), **draft.params}
    asset = Asset(
        asset_id=f"{name}-{seed}" if size is None else f"{name}-{seed}-{target:.4f}",
        name=name,
        category=name,
        source=source,
        seed=seed,
        spec=spec,
        aabb=aabb,
        mass=float(draft.root.mass() * scale**3),
        joints=joints,
        surfaces=surfaces,
        cavities=cavities,
        description="",
        params=params,
        features=list(draft.features),
    )
    asset.description = describe(name, asset, draft.features)
    return asset


# ----------------------------------------------------------------------------- registry

Generator = Callable[[np.random.Generator], Draft]
GENERATORS: dict[str, Generator] = {}


def register(*names: str):
    def deco(fn: Generator) -> Generator:
        for n in names:
            GENERATORS[n] = fn
        return fn

    return deco


def _load_generators() -> None:
    from anomalygen.assets.generators import appliances, furniture, household, small  # noqa: F401


def generate(name: str, seed: int, size: float | None = None) -> Asset:
    """A procedural asset for a vocabulary name; the same (name, seed, size) always gives the same asset."""
    from anomalygen.rng import item_rng

    _load_generators()
    if name not in GENERATORS:
        raise KeyError(f"no generator for {name!r}; known: {', '.join(sorted(GENERATORS))}")
    rng = item_rng(seed, "asset", name)
    draft = GENERATORS[name](rng)
    asset = finalize(draft, name=name, seed=seed, size=size, rng=rng)
    if size is not None:
        asset.params["requested_size"] = size
    return asset


def available_names() -> list[str]:
    _load_generators()
    return sorted(GENERATORS)


def math_deg(d: float) -> float:
    return d * math.pi / 180


def from_ref(ref: AssetRef) -> Asset:
    """Rebuild an asset from its reference (procedural: name + seed + size; imported: the path)."""
    if ref.source == AssetSource.PROCEDURAL:
        return generate(ref.category, int(ref.seed or 0), size=ref.params.get("size"))
    if ref.source == AssetSource.PARTNET and ref.path:
        from anomalygen.assets.importers import load_partnet

        return load_partnet(ref.path, size=ref.params.get("size"))
    if ref.source == AssetSource.OBJAVERSE and ref.path:
        from anomalygen.assets.importers import load_objaverse

        return load_objaverse(ref.path, size=ref.params.get("size"))
    raise ValueError(f"cannot rebuild asset {ref.asset_id!r} from source {ref.source}")
