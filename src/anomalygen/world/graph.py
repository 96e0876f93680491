"""The scene graph: what the robot perceives, computed from the *simulated* state only.

Detection reads this graph instead of the task, the skills stage evaluates success predicates over
graphs of final states, and the referee judges the settled end state on it, so it must be (1) faithful
to physics — support comes from contacts, "inside" from the containers' declared cavities (recorded
in scene.json as boxes on the bodies they move with), "under" from footprints, and an object the
suction cup holds rests on nothing — (2) the same for every object whatever part the builder gave
it (no roles are read), (3) free of any task text: it holds instance names, catalogue categories,
knowledge-base properties, geometry and joint values, never the task's name, description or hazard
class, and (4) cheap: per-model index tables are cached, the rest is a few vectorised numpy passes.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from anomalygen.mjgeom import FLOOR_GEOM, geom_world_aabbs
from anomalygen.scene_files import SCENE_SPEC, SCENE_XML
from anomalygen.schema import (
    LATCHING_PROPERTY,
    GraphObject,
    JointState,
    Relation,
    SceneGraph,
    SceneSpec,
    shut_by,
    within_child_reach,
)
from anomalygen.world.states import object_states
from anomalygen.world.tops import top_surface

if TYPE_CHECKING:  # pragma: no cover
    import mujoco

ON_FLOOR_TOL = 0.01  # m: bottom this close to z=0 counts as on the floor
NEAR_DIST = 0.15  # m: bounding-box gap below which two objects are "near"
CAVITY_TOL = 0.01  # m: an object's centre this far outside a cavity's box still counts as inside it
# m: below a cavity's floor face, more: generators shrink a compartment's declared box by its wall
# thickness, so a flat thing lying on a cupboard shelf (a USB stick, 7 mm) has its centre 1-2 cm under it
CAVITY_FLOOR_TOL = 0.05
UNDER_GAP = 0.02  # m: an object's top at least this far below another's top to lie under it


@dataclass(frozen=True)
class _Index:
    """Per-model lookup tables, built once per (model, spec) pair."""

    names: tuple[str, ...]
    geom_owner: np.ndarray  # geom id -> object index, -1 for robot/room
    floor_geom: int
    joint_ids: tuple[tuple[int, ...], ...]  # per object: joint ids matching its joint_states
    loose: np.ndarray  # per object: free to move (not welded to the world)
    latching: np.ndarray  # per object: a shut door or lid of it latches (LATCHING_PROPERTY)
    cav_owner: np.ndarray  # per cavity: object index
    cav_body: np.ndarray  # per cavity: the body it moves with
    cav_center: np.ndarray  # (K, 3) box centre in that body's frame
    cav_half: np.ndarray  # (K, 3)
    cav_volume: np.ndarray  # (K,)
    cav_closers: tuple[tuple[tuple[int, JointState], ...], ...]  # per cavity: (qpos address, joint) that shut it
    hold_eqs: np.ndarray  # weld constraints between an object body and a robot body
    hold_owner: np.ndarray  # the object each of them holds
    own_eqs: np.ndarray  # weld constraints between two robot bodies (the cup tracking its target)


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
    body_owner = np.full(model.nbody, -1, dtype=int)
    joint_ids = []
    for i, obj in enumerate(spec.objects):
        body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, obj.name)
        if body < 0:
            raise KeyError(f"scene model has no body for object {obj.name!r}")
        bodies = np.asarray(_subtree_bodies(model, body))
        body_owner[bodies] = i
        owner[np.isin(model.geom_bodyid, bodies)] = i
        jids = []
        for js in obj.joint_states:
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, js.name)
            if jid < 0:
                raise KeyError(f"scene model has no joint {js.name!r}")
            jids.append(jid)
        joint_ids.append(tuple(jids))
    floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, FLOOR_GEOM)
    props = _properties([o.asset.category for o in spec.objects])
    cav = _cavity_tables(model, spec)
    hold_eqs, hold_owner, own_eqs = _holding_welds(model, body_owner)
    idx = _Index(tuple(o.name for o in spec.objects), owner, floor, tuple(joint_ids),
                 np.array([not o.fixed for o in spec.objects], dtype=bool),
                 np.array([LATCHING_PROPERTY in p for p in props], dtype=bool), *cav, hold_eqs, hold_owner, own_eqs)
    per_model[key] = idx
    return idx


def _cavity_tables(model, spec: SceneSpec):
    """Every declared cavity of the scene as arrays, and the joints that must be shut to close each
    (``cavity_closers``)."""
    from anomalygen.world.cavities import cavities_of

    owners, bodies, centers, halves, closers = [], [], [], [], []
    for i, obj in enumerate(spec.objects):
        cavities = cavities_of(model, obj)
        for c, shut in zip(cavities, cavity_closers(obj.joint_states, [c.joint for c in cavities]), strict=True):
            owners.append(i)
            bodies.append(model.body(c.body).id)
            centers.append(c.center)
            halves.append(c.half_extents)
            closers.append(tuple((int(model.jnt_qposadr[model.joint(js.name).id]), js) for js in shut))
    half = np.asarray(halves, float).reshape(-1, 3)
    return (np.asarray(owners, int), np.asarray(bodies, int), np.asarray(centers, float).reshape(-1, 3), half,
            np.prod(2 * half, axis=1), tuple(closers))


def cavity_closers(joint_states: list[JointState], cavity_joints: list[str | None]) -> list[list[JointState]]:
    """Per cavity of one object (named by the joint it declares, or None), the joints that shut it.

    A cavity is shut by its own joint when that encloses (a door, drawer, lid or flap:
    ``JointState.encloses``); a cavity whose joint only moves it (an oven rack) or that names none is
    shut by all the object's enclosing parts. An enclosing part no cavity names (a fridge's second
    door, a box's second flap) must be shut too: either leaf open leaves the way in.
    """
    by_name = {js.name: js for js in joint_states}
    enclosing = [js for js in joint_states if js.encloses]
    named = {j for j in cavity_joints if j}
    orphans = [js for js in enclosing if js.name not in named]
    out = []
    for joint in cavity_joints:
        own = by_name.get(joint) if joint else None
        shut = ([own] if own is not None and own.encloses else enclosing) + orphans
        out.append(list({js.name: js for js in shut}.values()))
    return out


def _holding_welds(model, body_owner: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weld constraints that tie an object's body to a robot body (the suction cup's welds), the
    object each holds, and the welds between robot bodies alone (the cup tracking its target).

    Found from the model's structure, not from names: a weld with an object's body on one side and, on
    the other, a body that belongs to no object and is not the world.
    """
    import mujoco

    eqs, owners, robot_only = [], [], []
    for e in range(model.neq):
        if model.eq_type[e] != mujoco.mjtEq.mjEQ_WELD:
            continue
        ends = [int(model.eq_obj1id[e]), int(model.eq_obj2id[e])]
        if model.eq_objtype[e] == mujoco.mjtObj.mjOBJ_SITE:
            ends = [int(model.site_bodyid[s]) for s in ends]
        own = [int(body_owner[b]) for b in ends]
        objects = [o for o in own if o >= 0]
        robot_side = [b for b, o in zip(ends, own, strict=True) if o < 0 and b != 0]
        if len(objects) == 1 and robot_side:
            eqs.append(e)
            owners.append(objects[0])
        elif not objects and len(robot_side) == 2:
            robot_only.append(e)
    return np.asarray(eqs, int), np.asarray(owners, int), np.asarray(robot_only, int)


def geom_owners(model, spec: SceneSpec) -> np.ndarray:
    """Geom id -> index of the object it belongs to in ``spec.objects`` (-1: the robot or the room).
    A copy: the lookup table itself is shared by every caller of the same (model, spec)."""
    return _index(model, spec).geom_owner.copy()


def held_objects(model, data, spec: SceneSpec) -> list[str]:
    """Objects the robot's suction cup holds right now (an active object-to-robot weld, loose objects only)."""
    idx = _index(model, spec)
    return sorted({idx.names[o] for o in _held(idx, data)})


def holding_constraints(model, data, spec: SceneSpec) -> list[int]:
    """The active weld constraints by which the robot holds anything (objects or their parts)."""
    idx = _index(model, spec)
    return [int(e) for e in idx.hold_eqs[np.asarray(data.eq_active)[idx.hold_eqs] > 0]] if len(idx.hold_eqs) else []


def robot_constraints(model, data, spec: SceneSpec) -> list[int]:
    """Every active weld the robot exerts: what it holds, and its cup pulled towards a target (a limp
    arm tugged by that weld with nothing in contact made the referee's settle blow up)."""
    idx = _index(model, spec)
    own = [int(e) for e in idx.own_eqs[np.asarray(data.eq_active)[idx.own_eqs] > 0]] if len(idx.own_eqs) else []
    return holding_constraints(model, data, spec) + own


def _held(idx: _Index, data) -> set[int]:
    if not len(idx.hold_eqs):
        return set()
    on = np.asarray(data.eq_active)[idx.hold_eqs] > 0
    return {int(o) for o in idx.hold_owner[on] if idx.loose[o]}


def object_aabbs(model, data, owner: np.ndarray, n: int, geom_boxes=None) -> tuple[np.ndarray, np.ndarray]:
    """Per-object world AABB from its geoms (planes excluded); ``geom_boxes``: geom_world_aabbs' result."""
    lo, hi = geom_world_aabbs(model, data) if geom_boxes is None else geom_boxes
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
        nz = normal_z[k]
        if abs(nz) < 0.5:  # side contact: not support
            continue
        # geom above is the one the normal points to when nz > 0
        a, b = int(g1[k]), int(g2[k])
        upper, lower = (b, a) if nz > 0 else (a, b)
        ou, ol = owner[upper], owner[lower]
        if ou < 0 or ou == ol:
            continue
        if lower == floor:
            supports[ou]["floor"] = lower
        elif ol >= 0:
            supports[ou].setdefault(int(ol), lower)
    return supports


def _cavities_closed(idx: _Index, data) -> np.ndarray:
    """Per cavity: every joint that shuts it is (nearly) closed; a cavity nothing shuts is open."""
    qpos = data.qpos
    return np.array([shut_by((js, qpos[adr]) for adr, js in shut) for shut in idx.cav_closers], dtype=bool)


def _containment(idx: _Index, data, center: np.ndarray, held: set[int]) -> np.ndarray:
    """(K, N): the centre of object n lies inside cavity k (never its owner's own, never a held object)."""
    k, n = len(idx.cav_owner), len(center)
    if k == 0:
        return np.zeros((0, n), dtype=bool)
    pos = data.xpos[idx.cav_body]
    mats = data.xmat[idx.cav_body].reshape(k, 3, 3)
    origin = pos + np.einsum("kij,kj->ki", mats, idx.cav_center)
    local = np.einsum("kji,knj->kni", mats, center[None, :, :] - origin[:, None, :])  # R^T (c - o)
    half = idx.cav_half[:, None, :]
    within = np.all(np.abs(local[..., :2]) <= half[..., :2] + CAVITY_TOL, axis=2)
    within &= (local[..., 2] <= half[..., 2] + CAVITY_TOL) & (local[..., 2] >= -half[..., 2] - CAVITY_FLOOR_TOL)
    within[np.arange(k), idx.cav_owner] = False
    if held:
        within[:, sorted(held)] = False
    return within


def _under(lo, hi, center, supports, containers, held: set[int]) -> list[list[int]]:
    """Per object i, the objects j it lies under: its centre below j's footprint, its top below j's
    top, and neither resting on the other nor inside it (a knife on the floor under a table)."""
    n = len(center)
    in_xy = np.all((center[:, None, :2] > lo[None, :, :2]) & (center[:, None, :2] < hi[None, :, :2]), axis=2)
    lower = hi[:, None, 2] < hi[None, :, 2] - UNDER_GAP
    cand = in_xy & lower
    np.fill_diagonal(cand, False)
    out: list[list[int]] = [[] for _ in range(n)]
    for i, j in zip(*np.nonzero(cand), strict=True):
        i, j = int(i), int(j)
        if i in held or j in held or j in supports[i] or i in supports[j] or j in containers[i] or i in containers[j]:
            continue
        out[i].append(j)
    return out


def scene_graph(model: mujoco.MjModel, data: mujoco.MjData, spec: SceneSpec) -> SceneGraph:
    """The SceneGraph of the current simulated state (call after mj_forward or mj_step).

    The same rules for every object, whatever part the builder gave it: "inside" is inside a declared
    cavity (a table or chair has none), "under" is below another object's footprint without resting on
    it, and an object the suction cup holds rests on, in and under nothing.
    """
    idx = _index(model, spec)
    n = len(spec.objects)
    geom_lo, geom_hi = geom_world_aabbs(model, data)
    lo, hi = object_aabbs(model, data, idx.geom_owner, n, (geom_lo, geom_hi))
    held = _held(idx, data)
    supports = _support_contacts(model, data, idx.geom_owner, idx.floor_geom, n)
    for i in held:
        supports[i] = {}
    joints = [_joint_states(model, data, o, j) for o, j in zip(spec.objects, idx.joint_ids, strict=True)]
    props = _properties([o.asset.category for o in spec.objects])
    center = (lo + hi) / 2

    within = _containment(idx, data, center, held)
    closed = _cavities_closed(idx, data)
    containers: list[list[int]] = []  # per object: containing objects, smallest cavity first
    latched = np.zeros(n, dtype=bool)
    for i in range(n):
        ks = np.flatnonzero(within[:, i]) if len(within) else np.zeros(0, int)
        ks = np.array([k for k in ks if i not in supports[int(idx.cav_owner[k])]], dtype=int)  # it bears the container
        ks = ks[np.argsort(idx.cav_volume[ks], kind="stable")]
        owners = list(dict.fromkeys(int(idx.cav_owner[k]) for k in ks))
        containers.append(owners)
        latched[i] = any(closed[k] and idx.latching[idx.cav_owner[k]] for k in ks)
    under = _under(lo, hi, center, supports, [set(c) for c in containers], held)

    objects: list[GraphObject] = []
    relations: list[Relation] = []
    for i, obj in enumerate(spec.objects):
        height = float(lo[i][2])
        inside = containers[i]
        # low inside a bin is not on the floor: only a floor contact says so then (a bin's base is thin)
        on_floor = i not in held and ("floor" in supports[i] or (height < ON_FLOOR_TOL and not inside))
        edge = surface = None
        # distance from the object's footprint to the edge of its main support's top (the widest
        # supporting geom, grown by the level boards it adjoins; a laptop also touching a mug in the
        # middle of the table is not at an edge), in x/y; negative when the object overhangs.
        below = [g for sup, g in supports[i].items() if sup != "floor"]
        if below:
            geom = max(below, key=lambda g: float(np.prod(geom_hi[g][:2] - geom_lo[g][:2])))
            surface = top_surface(model, idx.geom_owner, (geom_lo, geom_hi), geom,
                                  model.body(spec.objects[int(idx.geom_owner[geom])].name).id)
            d = np.minimum(lo[i][:2] - surface[0][:2], surface[1][:2] - hi[i][:2])
            edge = float(np.min(d))
        objects.append(
            GraphObject(
                name=obj.name,
                category=obj.asset.category,
                called=obj.called,
                properties=props[i],
                position=[float(v) for v in center[i]],
                size=[float(v) for v in (hi[i] - lo[i])],
                height_above_floor=max(0.0, height),
                on_floor=on_floor,
                distance_to_edge=edge,
                child_reachable=within_child_reach(height, bool(latched[i])),
                joints=joints[i],
                held=i in held,
                states=object_states(model, data, obj, joints[i], surface),
            )
        )
        if on_floor:
            relations.append(Relation(subject=obj.name, predicate="on_floor"))
        for j in inside:
            relations.append(Relation(subject=obj.name, predicate="inside", object=spec.objects[j].name))
        for sup in supports[i]:
            if sup != "floor" and sup not in inside:
                relations.append(Relation(subject=obj.name, predicate="on", object=spec.objects[sup].name))
        for j in under[i]:
            relations.append(Relation(subject=obj.name, predicate="under", object=spec.objects[j].name))
    relations.extend(_near_relations(spec, lo, hi, containers, supports))
    return SceneGraph(scene_id=spec.scene_id, room=spec.room, objects=objects, relations=relations)


def _near_relations(spec: SceneSpec, lo, hi, containers, supports) -> list[Relation]:
    out = []
    n = len(spec.objects)
    for i in range(n):
        for j in range(i + 1, n):
            if j in containers[i] or i in containers[j] or j in supports[i] or i in supports[j]:
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
    spec = read_model(scene_dir / SCENE_SPEC, SceneSpec)
    model = mujoco.MjModel.from_xml_path(str(scene_dir / spec.files.get("xml", SCENE_XML)))
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
