"""The scene graph: what the robot perceives, computed from the *simulated* state only.

Detection reads this graph instead of the task, and the skills stage evaluates success predicates
over graphs of final states, so it must be (1) faithful to physics — relations come from contacts
and world bounding boxes, not from what the builder intended — (2) free of any task text: it holds
instance names, catalogue categories, knowledge-base properties, geometry and joint values, never
the task's name, description or hazard class, and (3) cheap: per-model index tables are cached, the
rest is a few vectorised numpy passes.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from anomalygen.scene.states import object_states
from anomalygen.schema import (
    CHILD_REACH,
    GraphObject,
    JointState,
    Relation,
    SceneGraph,
    SceneSpec,
)

if TYPE_CHECKING:  # pragma: no cover
    import mujoco

FLOOR_GEOM = "floor"
ON_FLOOR_TOL = 0.01  # m: bottom this close to z=0 counts as on the floor
NEAR_DIST = 0.15  # m: bounding-box gap below which two objects are "near"
# A door left ajar by under 10 % of its travel still shuts a child out: looser than joint_closed's
# CLOSED_TOL, which asks whether the robot finished closing it.
ENCLOSED_TOL = 0.1


@dataclass(frozen=True)
class _Index:
    """Per-model lookup tables, built once per (model, spec) pair."""

    names: tuple[str, ...]
    geom_owner: np.ndarray  # geom id -> object index, -1 for robot/room
    floor_geom: int
    joint_ids: tuple[tuple[int, ...], ...]  # per object: joint ids matching its joint_states


def _subtree_bodies(model, root: int) -> list[int]:
    out = [root]
    members = {root}
    for b in range(root + 1, model.nbody):
        if int(model.body_parentid[b]) in members:
            members.add(b)
            out.append(b)
    return out


# Keyed weakly on the model object itself (an id() could be reused by a later model).
_INDEX_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _index(model, spec: SceneSpec) -> _Index:
    import mujoco

    key = (spec.scene_id, tuple(o.name for o in spec.objects))
    per_model = _INDEX_CACHE.setdefault(model, {})
    cached = per_model.get(key)
    if cached is not None:
        return cached
    owner = np.full(model.ngeom, -1, dtype=int)
    joint_ids = []
    for i, obj in enumerate(spec.objects):
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, obj.name)
        if body < 0:
            raise KeyError(f"scene model has no body for object {obj.name!r}")
        bodies = np.asarray(_subtree_bodies(model, body))
        owner[np.isin(model.geom_bodyid, bodies)] = i
        jids = []
        for js in obj.joint_states:
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, js.name)
            if jid < 0:
                raise KeyError(f"scene model has no joint {js.name!r}")
            jids.append(jid)
        joint_ids.append(tuple(jids))
    floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, FLOOR_GEOM)
    idx = _Index(tuple(o.name for o in spec.objects), owner, floor, tuple(joint_ids))
    per_model[key] = idx
    return idx


def geom_world_aabbs(model, data) -> tuple[np.ndarray, np.ndarray]:
    """World-frame (min, max) corners of every geom's bounding box, shape (ngeom, 3) each."""
    import mujoco

    center_local = model.geom_aabb[:, :3]
    half_local = model.geom_aabb[:, 3:]
    mats = data.geom_xmat.reshape(-1, 3, 3)
    center = data.geom_xpos + np.einsum("gij,gj->gi", mats, center_local)
    half = np.einsum("gij,gj->gi", np.abs(mats), half_local)
    # Balls and ellipsoids get their exact box: the turned local box of a ball rolling in a basket
    # grew by up to 40 % (its bottom 3 cm under the floor) and the ball was no longer 'inside'.
    # (Capsules and cylinders keep the turned box: cable links and knobs are measured as before.)
    size, kind = model.geom_size, model.geom_type
    sph = kind == mujoco.mjtGeom.mjGEOM_SPHERE
    half[sph] = size[sph, :1]
    ell = kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID
    half[ell] = np.sqrt(np.einsum("gij,gj->gi", mats[ell] ** 2, size[ell] ** 2))
    return center - half, center + half


def object_aabbs(model, data, owner: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Per-object world AABB from its geoms (planes excluded)."""
    lo, hi = geom_world_aabbs(model, data)
    out_lo = np.full((n, 3), np.inf)
    out_hi = np.full((n, 3), -np.inf)
    valid = (owner >= 0) & (model.geom_type != 0)  # 0 = plane
    np.minimum.at(out_lo, owner[valid], lo[valid])
    np.maximum.at(out_hi, owner[valid], hi[valid])
    return out_lo, out_hi


def _joint_states(model, data, obj, jids) -> list[JointState]:
    out = []
    for js, jid in zip(obj.joint_states, jids, strict=True):
        value = float(data.qpos[model.jnt_qposadr[jid]])
        out.append(js.model_copy(update={"value": value}))
    return out


def _is_closed_enclosure(joints: list[JointState]) -> bool:
    """True when every door/drawer/lid of the object is (nearly) closed; False if it has none."""
    enclosing = [j for j in joints if j.encloses]
    return bool(enclosing) and all(j.is_closed(ENCLOSED_TOL) for j in enclosing)


def _support_contacts(model, data, owner: np.ndarray, floor: int, n: int):
    """For each object, the objects (and floor) below it that it touches: {obj: {support: geom}}."""
    supports: list[dict[str, int]] = [dict() for _ in range(n)]
    ncon = data.ncon
    if ncon == 0:
        return supports
    con = data.contact
    g1 = np.asarray(con.geom1[:ncon])
    g2 = np.asarray(con.geom2[:ncon])
    normal_z = np.asarray(con.frame[:ncon, 2])  # contact normal points from geom1 to geom2
    for k in range(ncon):
        a, b = int(g1[k]), int(g2[k])
        oa, ob = owner[a], owner[b]
        nz = normal_z[k]
        if abs(nz) < 0.5:  # side contact: not support
            continue
        # geom above is the one the normal points to when nz > 0
        upper, lower = (b, a) if nz > 0 else (a, b)
        ou, ol = owner[upper], owner[lower]
        if ou < 0 or ou == ol:
            continue
        if lower == floor:
            supports[ou]["floor"] = lower
        elif ol >= 0:
            supports[ou].setdefault(int(ol), lower)
        del oa, ob
    return supports


def scene_graph(model: mujoco.MjModel, data: mujoco.MjData, spec: SceneSpec) -> SceneGraph:
    """The SceneGraph of the current simulated state (call after mj_forward or mj_step)."""
    idx = _index(model, spec)
    n = len(spec.objects)
    lo, hi = object_aabbs(model, data, idx.geom_owner, n)
    geom_lo, geom_hi = geom_world_aabbs(model, data)
    supports = _support_contacts(model, data, idx.geom_owner, idx.floor_geom, n)
    joints = [_joint_states(model, data, o, j) for o, j in zip(spec.objects, idx.joint_ids, strict=True)]
    closed = [_is_closed_enclosure(j) for j in joints]
    props = _properties([o.asset.category for o in spec.objects])

    # inside: centre and most of the box within a container's box, not resting on its top.
    center = (lo + hi) / 2
    inside_of: list[int | None] = [None] * n
    for i in range(n):
        best_vol = np.inf
        for j in range(n):
            if i == j or spec.objects[j].role.value == "clutter" and not joints[j]:
                continue
            if not (np.all(center[i] > lo[j]) and np.all(center[i] < hi[j])):
                continue
            overlap = np.clip(np.minimum(hi[i], hi[j]) - np.maximum(lo[i], lo[j]), 0, None)
            vol_i = np.prod(np.clip(hi[i] - lo[i], 1e-6, None))
            if np.prod(overlap) < 0.8 * vol_i or lo[i][2] > hi[j][2] - 0.01:
                continue
            vol_j = np.prod(hi[j] - lo[j])
            if vol_j <= vol_i:
                continue
            if vol_j < best_vol:
                best_vol, inside_of[i] = vol_j, j

    objects: list[GraphObject] = []
    relations: list[Relation] = []
    for i, obj in enumerate(spec.objects):
        height = float(lo[i][2])
        container = inside_of[i]
        # low inside a bin is not on the floor: only a floor contact says so then (a bin's base is thin)
        on_floor = "floor" in supports[i] or (height < ON_FLOOR_TOL and container is None)
        edge = surface = None
        # distance from the object's footprint to the edge of its main support's top (the widest
        # supporting geom; a laptop also touching a mug in the middle of the table is not at an
        # edge), in x/y; negative when the object overhangs.
        under = [g for sup, g in supports[i].items() if sup != "floor"]
        if under:
            geom = max(under, key=lambda g: float(np.prod(geom_hi[g][:2] - geom_lo[g][:2])))
            d = np.minimum(lo[i][:2] - geom_lo[geom][:2], geom_hi[geom][:2] - hi[i][:2])
            edge = float(np.min(d))
            surface = (geom_lo[geom], geom_hi[geom])
        enclosed = container is not None and closed[container]
        objects.append(
            GraphObject(
                name=obj.name,
                category=obj.asset.category,
                properties=props[i],
                position=[float(v) for v in center[i]],
                size=[float(v) for v in (hi[i] - lo[i])],
                height_above_floor=max(0.0, height),
                on_floor=on_floor,
                distance_to_edge=edge,
                child_reachable=height <= CHILD_REACH and not enclosed,
                joints=joints[i],
                states=object_states(model, data, obj, joints[i], surface),
            )
        )
        if on_floor:
            relations.append(Relation(subject=obj.name, predicate="on_floor"))
        if container is not None:
            relations.append(
                Relation(subject=obj.name, predicate="inside", object=spec.objects[container].name)
            )
        for sup in supports[i]:
            if sup != "floor" and sup != container:
                relations.append(Relation(subject=obj.name, predicate="on", object=spec.objects[sup].name))
    relations.extend(_near_relations(spec, lo, hi, inside_of, supports))
    return SceneGraph(scene_id=spec.scene_id, room=spec.room, objects=objects, relations=relations)


def _near_relations(spec: SceneSpec, lo, hi, inside_of, supports) -> list[Relation]:
    out = []
    n = len(spec.objects)
    for i in range(n):
        for j in range(i + 1, n):
            if inside_of[i] == j or inside_of[j] == i or j in supports[i] or i in supports[j]:
                continue
            gap = np.maximum(0.0, np.maximum(lo[i] - hi[j], lo[j] - hi[i]))
            dist = float(np.linalg.norm(gap))
            if dist < NEAR_DIST:
                out.append(
                    Relation(
                        subject=spec.objects[i].name,
                        predicate="near",
                        object=spec.objects[j].name,
                        distance=round(dist, 4),
                    )
                )
    return out


def _properties(categories: list[str]) -> list[list[str]]:
    """Knowledge-base properties per category; objects the knowledge base does not know get none."""
    table = _kb_properties()
    return [list(table.get(c, table.get(c.lower(), ()))) for c in categories]


@lru_cache(maxsize=1)
def _kb_properties() -> dict[str, tuple[str, ...]]:
    from anomalygen.knowledge import load_kb

    kb = load_kb()
    out = {}
    for name, info in kb.objects.items():
        props = getattr(info, "properties", None) or []
        out[name] = tuple(str(getattr(p, "value", p)) for p in props)
    return out


def load_scene(scene_dir: str | Path):
    """Load a built scene: (model, data at the settled initial state, SceneSpec)."""
    import mujoco

    from anomalygen.runfolder import read_model

    scene_dir = Path(scene_dir)
    spec = read_model(scene_dir / "scene.json", SceneSpec)
    model = mujoco.MjModel.from_xml_path(str(scene_dir / spec.files.get("xml", "scene.xml")))
    data = mujoco.MjData(model)
    reset_to_initial(model, data)
    return model, data, spec


def reset_to_initial(model, data) -> None:
    """Reset to the settled state stored as keyframe ``init`` (or the model defaults)."""
    import mujoco

    key = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "init")
    if key >= 0:
        mujoco.mj_resetDataKeyframe(model, data, key)
    else:
        mujoco.mj_resetData(model, data)
    mujoco.mj_forward(model, data)
