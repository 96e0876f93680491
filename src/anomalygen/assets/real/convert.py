"""A packaged model's spec -> an ``Asset``: the same contract as a procedural one.

What the conversion fixes, and why:

- **Masses.** Packages set their own ``<compiler inertiagrouprange>`` (Franka Kitchen counts only
  group-4 geoms); attached into a scene with other settings, the masses change or vanish. So the
  source is compiled once with its own settings and every body gets those masses as an explicit
  inertial, scaled to the model's real mass: they then survive any attach.
- **Collisions.** Sources put collision geoms in a hidden group with ``contype=0`` (they touch the
  source's own robot, not loose objects). Every collision geom becomes ``contype=conaffinity=1`` in
  group 3 (hidden in renders), with MuJoCo's default contact parameters like the procedural assets;
  every visual geom touches nothing and weighs nothing.
- **Size and frame.** The model is scaled uniformly to its real size (or a requested one within
  ``SCALE_BAND`` of it), centred in x/y with its bottom at z = 0, front towards -y.
- **Self-contact.** Contacts among the model's own bodies are excluded (see ``finalize``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from anomalygen.assets.describe import describe
from anomalygen.assets.importers import exclude_self_contacts, scale_spec
from anomalygen.assets.model import Asset, AssetJoint, Cavity, Surface
from anomalygen.schema import AssetSource

SCALE_BAND = (0.8, 1.25)  # a real model is rescaled at most this far from its real size
MIN_MASS = 1e-3  # kg: a moving body needs mass (a knob's, a burner's)
MIN_INERTIA = 1e-7  # kg m^2
COLLISION_GROUP = 3  # where collision geoms go: hidden in renders, like the sources' groups 3/4
VISUAL_GROUP = 1
MESH = 7  # mujoco.mjtGeom.mjGEOM_MESH
# Joint damping and armature per unit of the moving part's inertia about its joint, as the procedural
# parts have them (``finalize._joint_gains``): the sources' own values (a damping of 2 on a 20 g
# knob) are tuned for their robot and leave a knob turning for seconds under a servo.
DAMPING_PER_INERTIA = 2.0  # 1/s
ARMATURE_PER_INERTIA = 0.2


@dataclass
class Raw:
    """A packaged model as its loader leaves it: front -y, source units, root body ``root``."""

    spec: Any  # mujoco.MjSpec with the source's compiler settings
    joints: dict[str, tuple[str, float]]  # every hinge/slide joint -> (label, closed value)
    collision_group: int  # the source's group of collision geoms
    surfaces: list[Surface] = field(default_factory=list)  # source frame
    cavities: list[Cavity] = field(default_factory=list)  # source frame
    parts: dict[str, list[str]] = field(default_factory=dict)  # handle/burner -> geom names
    features: list[str] = field(default_factory=list)  # words for the description
    front: tuple[float, float] | None = None  # the side it is worked from, if no door says so
    # joint -> (damping, dry friction) replacing the inertia-scaled defaults (N m s/rad and N m)
    resistance: dict[str, tuple[float, float]] = field(default_factory=dict)


def _aabb(model, data) -> tuple[np.ndarray, np.ndarray]:
    """The exact box of every geom: a mesh's own vertices (its ``geom_aabb`` lives in the mesh's
    principal frame, which can be turned, and turned back it is up to 40 % too big)."""
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for g in range(model.ngeom):
        rot = data.geom_xmat[g].reshape(3, 3)
        if model.geom_type[g] == MESH:
            mesh = model.geom_dataid[g]
            start = model.mesh_vertadr[mesh]
            pts = data.geom_xpos[g] + model.mesh_vert[start : start + model.mesh_vertnum[mesh]] @ rot.T
            lo, hi = np.minimum(lo, pts.min(0)), np.maximum(hi, pts.max(0))
            continue
        c = data.geom_xpos[g] + rot @ model.geom_aabb[g, :3]
        h = np.abs(rot) @ model.geom_aabb[g, 3:]
        lo, hi = np.minimum(lo, c - h), np.maximum(hi, c + h)
    return lo, hi


def _rotations() -> list[np.ndarray]:
    """The 24 proper rotations that map axes onto axes (signed permutation matrices, det +1)."""
    import itertools

    out = []
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1.0, -1.0), repeat=3):
            p = np.zeros((3, 3))
            p[list(range(3)), list(perm)] = signs
            if np.linalg.det(p) > 0:
                out.append(p)
    return out


def aligning_quat(spec, geom_name: str) -> np.ndarray:
    """The smallest turn of the whole model that lines the named mesh geom's frame up with the axes.

    The scene graph's boxes are MuJoCo's ``geom_aabb`` (a box in the mesh's principal frame) turned
    into the world: tight only when that frame is axis-aligned. Turned by this quaternion, the model's
    main mesh has an exact box."""
    import mujoco

    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    rot = data.geom(geom_name).xmat.reshape(3, 3)
    best = max(_rotations(), key=lambda p: float(np.trace(p.T @ rot)))
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, (best @ rot.T).reshape(9))
    return quat


def _source_inertials(spec) -> tuple[dict[str, tuple], tuple[np.ndarray, np.ndarray]]:
    """Per-body (mass, ipos, iquat, inertia) and the AABB, as the source's own compiler makes them."""
    import mujoco

    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    inertials = {
        model.body(b).name: (
            float(model.body_mass[b]),
            model.body_ipos[b].copy(),
            model.body_iquat[b].copy(),
            model.body_inertia[b].copy(),
        )
        for b in range(1, model.nbody)
    }
    return inertials, _aabb(model, data)


def _set_inertials(spec, inertials: dict[str, tuple], s: float, k: float, offset: np.ndarray) -> None:
    """Explicit inertials from the source compile: mass x k, lengths x s (the root's moved by ``offset``)."""
    for b in spec.bodies:
        if b.name == "world":
            continue
        mass, ipos, iquat, inertia = inertials[b.name]
        if mass <= 0.0 and not b.joints:
            continue  # a massless static body (a frame holding the parts) stays massless
        b.explicitinertial = True
        b.mass = max(mass * k, MIN_MASS)
        b.ipos = ipos * s + (offset if b.name == "root" else 0.0)
        b.iquat = iquat
        b.inertia = np.maximum(inertia * k * s * s, MIN_INERTIA)


def _normalise_geoms(spec, collision_group: int) -> None:
    """Collision geoms collide with everything, hidden; visual ones touch nothing and weigh nothing."""
    for g in spec.geoms:
        if g.group == collision_group and (g.contype or g.conaffinity):
            g.contype, g.conaffinity, g.group = 1, 1, COLLISION_GROUP
            g.condim, g.margin, g.gap, g.priority = 3, 0.0, 0.0, 0
            g.friction = [1.0, 0.005, 0.0001]
            g.solref = [0.02, 1.0]
            g.solimp = [0.9, 0.95, 0.001, 0.5, 2.0]
        else:
            g.contype, g.conaffinity, g.group = 0, 0, VISUAL_GROUP
        g.density, g.mass = 0.0, 0.0


def _tune_joints(spec, resistance: dict[str, tuple[float, float]]) -> None:
    """Damping and armature from each joint's own inertia, no dry friction (as procedural parts),
    unless the loader declares the part's own resistance."""
    import mujoco

    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    for j in range(model.njnt):
        dof = model.jnt_dofadr[j]
        unit, out = np.zeros(model.nv), np.zeros(model.nv)
        unit[dof] = 1.0
        mujoco.mj_mulM(model, data, out, unit)
        inertia = max(float(out[dof]) - float(model.dof_armature[dof]), 0.0)
        joint = spec.joint(model.joint(j).name)
        damping, friction = resistance.get(joint.name, (DAMPING_PER_INERTIA * inertia, 0.0))
        joint.damping = [max(damping, 1e-5), 0.0, 0.0]
        joint.armature = max(ARMATURE_PER_INERTIA * inertia, 1e-6)
        joint.frictionloss = float(friction)
        joint.stiffness = [0.0, 0.0, 0.0]


def _joints(model, data, declared: dict[str, tuple[str, float]], s: float) -> list[AssetJoint]:
    import mujoco

    out = []
    for j in range(model.njnt):
        name = model.joint(j).name
        kind = int(model.jnt_type[j])
        if kind not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            raise ValueError(f"packaged model joint {name!r} is neither a hinge nor a slide")
        if name not in declared:
            raise ValueError(f"packaged model joint {name!r} has no declared label and closed value")
        label, closed = declared[name]
        hinge = kind == mujoco.mjtJoint.mjJNT_HINGE
        out.append(
            AssetJoint(
                name=name,
                type="hinge" if hinge else "slide",
                range=(float(model.jnt_range[j][0]), float(model.jnt_range[j][1])),
                label=label,
                closed_value=float(closed if hinge else closed * s),
                axis=tuple(round(float(a), 6) for a in data.xaxis[j]),
                body=model.body(int(model.jnt_bodyid[j])).name,
            )
        )
    return out


def to_asset(raw: Raw, *, key: str, category: str, real_size: float, real_mass: float,
             size: float | None, package: str, licence: str) -> Asset:
    """Scale ``raw`` to ``size`` (clamped to ``SCALE_BAND`` around ``real_size``), fix masses and
    collisions, centre it, and describe it as an ``Asset`` of ``category``."""
    import mujoco

    from anomalygen.assets.finalize import new_spec

    spec = raw.spec
    inertials, (lo, hi) = _source_inertials(spec)
    nominal = float(np.max(hi - lo))
    target = real_size if size is None else float(np.clip(size, real_size * SCALE_BAND[0], real_size * SCALE_BAND[1]))
    s = target / nominal
    source_mass = sum(m for m, *_ in inertials.values())
    k = real_mass * (target / real_size) ** 3 / max(source_mass, 1e-9)
    offset = -np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]]) * s
    _set_inertials(spec, inertials, s, k, offset)
    _normalise_geoms(spec, raw.collision_group)
    if spec.worldbody.first_body().frames:
        raise ValueError("a packaged model's root body may not hold frames")
    scale_spec(spec, s, root_offset=offset)
    defaults = new_spec().compiler
    spec.compiler.degree = defaults.degree
    spec.compiler.autolimits = True
    spec.compiler.inertiagrouprange = defaults.inertiagrouprange
    exclude_self_contacts(spec)
    _tune_joints(spec, raw.resistance)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)

    def tf(p):
        return tuple(float(v) for v in np.asarray(p) * s + offset)

    ext = (hi - lo) * s
    aabb = (np.array([-ext[0] / 2, -ext[1] / 2, 0.0]), np.array([ext[0] / 2, ext[1] / 2, ext[2]]))
    params = {"model": key, "size": round(target, 5), "scale": round(s, 6), "parts": raw.parts}
    asset = Asset(
        asset_id=key if size is None else f"{key}-{target:.4f}",
        name=category,
        category=category,
        source=AssetSource.PACKAGED,
        seed=None,
        spec=spec,
        aabb=aabb,
        mass=float(model.body_subtreemass[1]),
        joints=_joints(model, data, raw.joints, s),
        surfaces=[Surface(x.name, tf(x.center), (x.half_size[0] * s, x.half_size[1] * s)) for x in raw.surfaces],
        cavities=[Cavity(c.name, tf(c.center), tuple(h * s for h in c.half_extents), c.opening, c.joint)
                  for c in raw.cavities],
        description="",
        params=params,
        features=list(raw.features),
        package=package,
        licence=licence,
        front=raw.front,
    )
    asset.description = describe(category, asset, [*raw.features, f"a real model from the {package} package"])
    return asset
