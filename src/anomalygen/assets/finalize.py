"""The step that turns a generator's draft into an Asset: scale, centre, emit the MjSpec, describe it."""

from __future__ import annotations

import numpy as np

from anomalygen.assets.describe import describe
from anomalygen.assets.model import Asset, AssetJoint, Cavity, Draft, Surface
from anomalygen.assets.names import size_range
from anomalygen.assets.parts import Part
from anomalygen.schema import AssetSource


def _joint_gains(part: Part, scale: float) -> tuple[float, float]:
    """Damping and armature proportional to the moving subtree's inertia, so small caps and heavy
    fridge doors both settle in a fraction of a second instead of ringing or freezing."""
    j = part.joint
    if j.type == "slide":
        eff = part.mass() * scale**3
    else:
        eff = part.subtree_inertia(np.asarray(j.pos)) * scale**5
    return max(2.0 * eff, 1e-5), max(0.2 * eff, 1e-6)


LATCH_FORCE = 2.0  # N that moves a latched slide (a switch's click)
HARD_SOLREF = [0.004, 1.0]  # s time constant (twice the 2 ms step), damping ratio
HARD_SOLIMP = [0.999, 0.9999, 0.001, 0.5, 2.0]  # impedance near 1: the constraint hardly yields

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
            if j.type == "slide":
                # A small slide held by friction (a push switch, a snuffer) is a latch: a weight's
                # worth of friction let the jolt of a power strip dropped into a basin knock it off;
                # MuJoCo's default soft friction lets it creep ~5 mm/s under gravity (left on, it
                # switched itself off while the scene settled), and its soft end stops, scaled by its
                # few grams, let a cup push it a centimetre through them; near-hard constraints creep
                # ~0.02 mm/s and stop it (the friction's force is still capped by the frictionloss)
                joint.frictionloss = max(joint.frictionloss, LATCH_FORCE)
                joint.solref_friction = joint.solref_limit = HARD_SOLREF
                joint.solimp_friction = joint.solimp_limit = HARD_SOLIMP
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
        Cavity(c.name, tf(c.center), tuple(h * scale for h in c.half_extents), c.opening, c.joint, c.open_above)
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
        front_access=draft.front_access,
    )
    asset.description = describe(name, asset, draft.features)
    return asset
