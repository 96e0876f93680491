"""Importers for assets a user has on disk: PartNet-Mobility model folders and Objaverse-style meshes.

Both produce the same ``Asset`` as the procedural generators (one ``root`` body, bottom at z = 0,
centred, compiler in radians), so downstream stages cannot tell them apart.

PartNet-Mobility: ``mobility.urdf`` + ``meta.json`` + ``semantics.txt`` + ``textured_objs/*.obj``.
MuJoCo's URDF reader fails on ``package://`` paths and drops visuals by default, so we strip the
scheme and inject ``<mujoco><compiler meshdir=... strippath="true" discardvisual="false"/></mujoco>``.
Models are Y-up; they are rotated to Z-up.

Objaverse: OBJ files plus an annotations JSON (Objaverse's per-uid records: name, tags, categories,
description). GLB would need trimesh to convert, which is not a dependency; GLB is refused with a
message saying so.
"""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from anomalygen.assets.finalize import new_spec
from anomalygen.assets.model import Asset, AssetJoint
from anomalygen.assets.names import size_range
from anomalygen.errors import UserError
from anomalygen.schema import AssetSource

_Y_UP_TO_Z_UP = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0)  # +90 deg about x


def _world_aabb(model, data) -> tuple[np.ndarray, np.ndarray]:
    """Bounding box of all geoms (via each geom's local AABB) in world coordinates."""
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)
    for g in range(model.ngeom):
        if model.geom_bodyid[g] == 0:
            continue
        c, h = model.geom_aabb[g, :3], model.geom_aabb[g, 3:]
        corners = c + signs * h
        world = data.geom_xpos[g] + corners @ data.geom_xmat[g].reshape(3, 3).T
        lo, hi = np.minimum(lo, world.min(0)), np.maximum(hi, world.max(0))
    return lo, hi


def scale_spec(spec, s: float, root_offset=None) -> None:
    """Uniformly scale positions, sizes, meshes and slide ranges of a spec in place; with
    ``root_offset`` (already scaled) also move everything the body named ``root`` holds."""
    import mujoco

    off = np.zeros(3) if root_offset is None else np.asarray(root_offset, float)

    def shift(el) -> np.ndarray:
        return off if el.parent.name == "root" else np.zeros(3)

    for b in spec.bodies:
        if b.name != "world":
            b.pos = np.asarray(b.pos) * s + shift(b)
    for g in spec.geoms:
        g.pos = np.asarray(g.pos) * s + shift(g)
        if not np.isnan(g.fromto[0]):
            g.fromto = np.asarray(g.fromto) * s + np.r_[shift(g), shift(g)]
        if g.type != mujoco.mjtGeom.mjGEOM_MESH:
            g.size = np.asarray(g.size) * s
    for m in spec.meshes:
        m.scale = np.asarray(m.scale) * s
    for j in spec.joints:
        j.pos = np.asarray(j.pos) * s
        if j.type == mujoco.mjtJoint.mjJNT_SLIDE:
            j.range = np.asarray(j.range) * s
    for site in spec.sites:
        site.pos = np.asarray(site.pos) * s + shift(site)
        site.size = np.asarray(site.size) * s


_TMP_PREFIX = "imp__"


def _attach_unprefixed(spec, frame, child) -> None:
    """Attach ``child``'s first body keeping the original names (MuJoCo warns on an empty prefix,
    so attach with a temporary prefix and strip it)."""
    frame.attach_body(child.worldbody.first_body(), _TMP_PREFIX, "")
    for group in (
        spec.bodies,
        spec.joints,
        spec.geoms,
        spec.meshes,
        spec.sites,
        spec.materials,
        spec.textures,
    ):
        for el in group:
            if el.name.startswith(_TMP_PREFIX):
                el.name = el.name[len(_TMP_PREFIX) :]
    for m in spec.geoms:
        if m.meshname.startswith(_TMP_PREFIX):
            m.meshname = m.meshname[len(_TMP_PREFIX) :]


def exclude_self_contacts(spec) -> None:
    """No contacts among the model's own links (doors must not jam on their frame; see core)."""
    names = [b.name for b in spec.bodies if b.name != "world"]
    for i, a in enumerate(names):
        for b in names[i + 1 :]:
            ex = spec.add_exclude()
            ex.bodyname1, ex.bodyname2 = a, b


def _wrap(inner_spec, *, up_quat, size: float | None, default_size: float):
    """Rotate, scale and centre an imported spec under a fresh ``root`` body; returns (spec, aabb, mass, scale)."""
    import mujoco

    probe = new_spec()
    frame = probe.worldbody.add_body(name="root").add_frame(quat=list(up_quat))
    _attach_unprefixed(probe, frame, inner_spec.copy())
    model = probe.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    lo, hi = _world_aabb(model, data)
    nominal = float(np.max(hi - lo))
    target = default_size if size is None else size
    s = target / nominal
    scaled = inner_spec.copy()
    scale_spec(scaled, s)
    spec = new_spec()
    root = spec.worldbody.add_body(name="root")
    off = -np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, lo[2]]) * s
    f = root.add_frame(pos=list(off), quat=list(up_quat))
    _attach_unprefixed(spec, f, scaled)
    exclude_self_contacts(spec)
    model = spec.compile()
    mass = float(model.body_subtreemass[1]) if model.nbody > 1 else 0.0
    ext = (hi - lo) * s
    aabb = (np.array([-ext[0] / 2, -ext[1] / 2, 0.0]), np.array([ext[0] / 2, ext[1] / 2, ext[2]]))
    return spec, aabb, mass, s


# ----------------------------------------------------------------------------- PartNet-Mobility


def read_semantics(path: Path) -> dict[str, tuple[str, str]]:
    """``semantics.txt`` lines ``link_name joint_kind label`` -> {link: (kind, label)}."""
    out = {}
    if path.exists():
        for line in path.read_text().splitlines():
            parts = line.split()
            if len(parts) >= 3:
                out[parts[0]] = (parts[1], parts[2])
    return out


def prepare_urdf(urdf_text: str, mesh_dir: Path) -> str:
    """Strip ``package://`` from mesh paths and add MuJoCo's compiler block (keep visuals, keep links)."""
    root = ET.fromstring(urdf_text)
    for mesh in root.iter("mesh"):
        fn = mesh.get("filename", "")
        if fn.startswith("package://"):
            fn = fn[len("package://") :]
        mesh.set("filename", fn)
    for old in root.findall("mujoco"):
        root.remove(old)
    mj = ET.SubElement(root, "mujoco")
    ET.SubElement(
        mj,
        "compiler",
        meshdir=str(mesh_dir),
        strippath="true",
        discardvisual="false",
        fusestatic="false",
        balanceinertia="true",
    )
    return ET.tostring(root, encoding="unicode")


def load_partnet(path: str | Path, *, size: float | None = None, up_axis: str = "y") -> Asset:
    """Import a PartNet-Mobility model folder as an articulated Asset with labelled joints."""
    import mujoco

    folder = Path(path)
    urdf_path = folder / "mobility.urdf"
    if not urdf_path.exists():
        raise UserError(f"{folder}: no mobility.urdf (not a PartNet-Mobility model folder)")
    meta = json.loads((folder / "meta.json").read_text()) if (folder / "meta.json").exists() else {}
    category = str(meta.get("model_cat") or meta.get("category") or "Unknown")
    semantics = read_semantics(folder / "semantics.txt")
    urdf_root = ET.fromstring(urdf_path.read_text())
    mesh_files = [m.get("filename", "") for m in urdf_root.iter("mesh")]
    mesh_dir = folder
    if mesh_files:
        first = mesh_files[0].removeprefix("package://")
        mesh_dir = (folder / first).parent if (folder / first).exists() else folder / "textured_objs"
    xml = prepare_urdf(urdf_path.read_text(), mesh_dir)
    try:
        inner = mujoco.MjSpec.from_string(xml)
    except Exception as exc:
        raise UserError(f"{folder}: MuJoCo cannot read the URDF: {exc}") from exc
    inner.compiler.degree = False
    for m in inner.meshes:
        m.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX  # PartNet meshes are rarely watertight
    for g in inner.geoms:
        g.density = 120.0  # convex hulls of mostly hollow furniture and appliances
    up = _Y_UP_TO_Z_UP if up_axis == "y" else (1.0, 0.0, 0.0, 0.0)
    lo_hi = size_range(category) if _known(category) else (0.05, 3.0)
    default = float(np.mean(lo_hi))
    spec, aabb, mass, s = _wrap(
        inner, up_quat=up, size=None if size is None else float(size), default_size=default
    )
    joints = []
    child_of = {
        j.get("name"): (j.find("child").get("link") if j.find("child") is not None else "")
        for j in urdf_root.iter("joint")
    }
    model = spec.compile()
    for j in spec.joints:
        if j.type not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            continue
        link = child_of.get(j.name, "")
        kind, label = semantics.get(link, ("", "part"))
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j.name)
        rng = tuple(float(v) for v in model.jnt_range[jid]) if model.jnt_limited[jid] else (-math.pi, math.pi)
        closed = 0.0 if rng[0] <= 0.0 <= rng[1] else rng[0]
        joints.append(
            AssetJoint(
                j.name,
                "hinge" if j.type == mujoco.mjtJoint.mjJNT_HINGE else "slide",
                rng,
                label,
                closed,
                tuple(float(a) for a in j.axis),
                link,
            )
        )
    labels = sorted({j.label for j in joints})
    desc = f"{category} imported from PartNet-Mobility model {meta.get('anno_id', folder.name)}; about {float(np.max(aabb[1] - aabb[0])) * 100:.0f} cm; movable parts: {', '.join(labels) or 'none'}"
    return Asset(
        asset_id=f"partnet:{meta.get('anno_id', folder.name)}",
        name=category,
        category=category,
        source=AssetSource.PARTNET,
        seed=None,
        spec=spec,
        aabb=aabb,
        mass=mass,
        joints=joints,
        surfaces=[],
        cavities=[],
        description=desc,
        params={
            "size": round(float(np.max(aabb[1] - aabb[0])), 5),
            "scale": s,
            "up_axis": up_axis,
            "semantics": {k: list(v) for k, v in semantics.items()},
        },
        path=str(folder),
    )


def _known(name: str) -> bool:
    try:
        size_range(name)
        return True
    except KeyError:
        return False


# ----------------------------------------------------------------------------- Objaverse


def read_annotation(annotations: Path | dict | None, uid: str) -> dict:
    if annotations is None:
        return {}
    data = annotations if isinstance(annotations, dict) else json.loads(Path(annotations).read_text())
    rec = data.get(uid, data if "name" in data else {})
    return rec if isinstance(rec, dict) else {}


def _names(items) -> list[str]:
    return [i.get("name", "") if isinstance(i, dict) else str(i) for i in (items or [])]


def load_objaverse(
    path: str | Path,
    *,
    annotations: str | Path | dict | None = None,
    size: float | None = None,
    name: str | None = None,
    up_axis: str = "y",
    density: float = 500.0,
) -> Asset:
    """Import one Objaverse-style mesh (OBJ) as a rigid Asset; ``annotations`` gives its text."""
    import mujoco

    mesh_path = Path(path)
    if not mesh_path.exists():
        raise UserError(f"{mesh_path}: file not found")
    if mesh_path.suffix.lower() in (".glb", ".gltf"):
        try:
            import trimesh  # noqa: F401  (optional; converts GLB to OBJ if the user has it)
        except ImportError:
            raise UserError(
                f"{mesh_path.name}: GLB import needs the optional 'trimesh' package; install it or convert the file to OBJ"
            ) from None
        mesh_path = _glb_to_obj(mesh_path)
    if mesh_path.suffix.lower() != ".obj":
        raise UserError(f"{mesh_path.name}: only OBJ (or GLB with trimesh) is supported")
    uid = mesh_path.stem
    if annotations is None and (mesh_path.parent / "annotations.json").exists():
        annotations = mesh_path.parent / "annotations.json"
    ann = read_annotation(annotations, uid)
    label = name or ann.get("name") or uid
    inner = new_spec()
    inner.add_mesh(
        name="mesh", file=str(mesh_path.resolve()), inertia=mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX
    )
    body = inner.worldbody.add_body(name="mesh_body")
    body.add_geom(
        type=mujoco.mjtGeom.mjGEOM_MESH, meshname="mesh", density=density, rgba=[0.75, 0.72, 0.68, 1]
    )
    up = _Y_UP_TO_Z_UP if up_axis == "y" else (1.0, 0.0, 0.0, 0.0)
    key = label.lower().replace(" ", "_")
    default = float(np.mean(size_range(key))) if _known(key) else 0.3
    spec, aabb, mass, s = _wrap(inner, up_quat=up, size=size, default_size=default)
    tags = _names(ann.get("tags"))
    cats = _names(ann.get("categories"))
    extent = float(np.max(aabb[1] - aabb[0]))
    desc = "; ".join(
        x
        for x in [
            f"{label} (Objaverse {uid})",
            f"about {extent * 100:.0f} cm",
            ann.get("description", ""),
            ", ".join(tags[:10]),
            ", ".join(cats),
        ]
        if x
    )
    return Asset(
        asset_id=f"objaverse:{uid}",
        name=label,
        category=key if _known(key) else (cats[0] if cats else "objaverse"),
        source=AssetSource.OBJAVERSE,
        seed=None,
        spec=spec,
        aabb=aabb,
        mass=mass,
        joints=[],
        surfaces=[],
        cavities=[],
        description=desc,
        params={"size": round(extent, 5), "scale": s, "up_axis": up_axis, "uid": uid},
        path=str(Path(path)),
    )


def _glb_to_obj(path: Path) -> Path:
    import tempfile

    import trimesh

    mesh = trimesh.load(path, force="mesh")
    out = Path(tempfile.mkdtemp(prefix="ag-glb-")) / f"{path.stem}.obj"
    mesh.export(out)
    return out
