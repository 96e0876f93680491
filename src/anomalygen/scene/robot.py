"""The robot: a Franka Panda arm with a suction cup, on a mobile base (planar x, y, yaw).

Source of the arm: the Franka Panda MJCF and meshes shipped by the ``gymnasium-robotics`` wheel
(``gymnasium_robotics/envs/assets/kitchen_franka/franka_assets/``, MIT; itself modified from
github.com/vikashplus/franka, Apache-2.0). We read its ``assets.xml`` and ``chain.xml`` at build
time rather than copying them, drop the two parallel fingers (our gripper is a suction cup, as in the
paper) and rename joints to plain ``panda_joint1..7``.

Why a mobile base: household hazards lie on the floor, on counters and on shelves across a room; a
fixed arm reaches none of that. Three joints (``base_x``, ``base_y`` slide, ``base_yaw`` hinge) move
the base on the floor, with position actuators of the same names. Why a torso lift (body ``torso``
under the arm, as on Fetch, TIAGo or Stretch): with the arm's shoulder at counter height the cup
cannot reach, face-down, the lid of a box that stands on a 0.9 m counter; raised by up to
``LIFT_MAX`` it can. It rests at 0, where the arm reaches the floor; ``set_lift`` moves it.

Names other stages rely on (see docs/scene.md):

* joints ``base_x base_y base_yaw panda_joint1 .. panda_joint7`` (``ROBOT_JOINTS``), each with a
  position actuator of the same name (``ctrl`` = target joint value);
* bodies ``base``, ``torso`` (carried by the lift), ``panda_link0 .. panda_link7``, ``suction`` (the cup);
* sites ``ee_site`` (tool frame, z axis pointing out of the cup) and ``suction_site`` (cup face);
* mocap body ``ee_target`` and weld ``ee_track`` (inactive unless the Gymnasium env drives the arm
  by end-effector deltas);
* welds ``suction__<object>`` from the cup to each free object, all inactive at build time; toggle
  them with :func:`suction_on` / :func:`suction_off`.
* ``set_home``: base joints at the scene's base pose, arm at ``HOME_ARM`` (cup pointing down);
  built scenes store their settled start state as keyframe ``init``.
"""

from __future__ import annotations

import re
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    import mujoco

ARM_JOINTS = tuple(f"panda_joint{i}" for i in range(1, 8))
BASE_JOINTS = ("base_x", "base_y", "base_yaw")
ROBOT_JOINTS = BASE_JOINTS + ARM_JOINTS
# A tucked arm pose with the cup pointing straight down 0.3 m in front of the base at 1.01 m height
# (found by forward kinematics; tests check it): tucked and above counter height, so the base can
# drive up to tables and counters without the arm hitting them.
HOME_ARM = (0.0, -0.5, 0.0, -1.55, 0.0, -0.55, -0.785)
BASE_HEIGHT = 0.30  # top of the mobile base, where the arm's link0 stands with the lift down
LIFT_MAX = 0.30  # metres the torso lift raises the arm
BASE_RADIUS = 0.22
SUCTION_RANGE = 0.012  # metres: how far from the cup face an object may be and still be grabbed
SUCTION_PREFIX = "suction__"
ROBOT_BODY_PREFIXES = ("base", "torso", "panda_", "suction", "ee_target")
# Arm position gains from the source actuator.xml (kp and force limits of each joint).
_ARM_GAINS = ((870, 87), (870, 87), (870, 87), (870, 87), (120, 12), (120, 12), (120, 12))


def franka_assets_dir() -> Path:
    """The installed gymnasium-robotics Franka folder (MJCF + meshes)."""
    import importlib.util

    found = importlib.util.find_spec("gymnasium_robotics")  # no import: the package warns on import
    if found is None or not found.submodule_search_locations:  # pragma: no cover
        from anomalygen.errors import UserError

        raise UserError("gymnasium-robotics is not installed (it provides the Franka Panda model)")
    path = (
        Path(list(found.submodule_search_locations)[0])
        / "envs"
        / "assets"
        / "kitchen_franka"
        / "franka_assets"
    )
    if not (path / "chain.xml").is_file():  # pragma: no cover - broken installation
        from anomalygen.errors import UserError

        raise UserError(f"Franka assets not found at {path}; reinstall gymnasium-robotics")
    return path


def _strip_include(text: str) -> str:
    text = re.sub(r"<!--.*?-->", "", text, flags=re.S)
    text = re.sub(r"</?mujocoinclude>", "", text)
    return text


@lru_cache(maxsize=1)
def _arm_xml() -> str:
    """One MJCF string holding the source's defaults, mesh assets and arm chain (fingers removed)."""
    root = franka_assets_dir()
    assets = _strip_include((root / "assets.xml").read_text())
    assets = re.sub(r"<compiler[^>]*/>", "", assets)
    assets = re.sub(r"<option[^>]*/>", "", assets)
    assets = re.sub(r"<size[^>]*/>", "", assets)
    # Render with the collision meshes (120 KB) instead of the 6.5 MB visual ones: software EGL
    # rendering and mesh upload were 3-5x slower with them, and the scene builder renders 3 views
    # of every scene within its per-scene budget. The arm still reads clearly as a Panda.
    assets = re.sub(r'<mesh name="\w+_viz"[^>]*/>', "", assets)
    chain = _strip_include((root / "chain.xml").read_text())
    chain = re.sub(r'mesh="(\w+)_viz"', r'mesh="\1_col"', chain)
    chain = chain.replace("robot:panda0_joint", "panda_joint").replace(
        'name="panda0_link', 'name="panda_link'
    )
    chain = re.sub(r"<body name=\"panda0_(left|right)finger\".*?</body>", "", chain, flags=re.S)
    chain = re.sub(r"<site name='end_effector'[^>]*/>", "", chain)
    chain = chain.replace('<body name="panda_link0"', f'<body name="panda_link0" pos="0 0 {BASE_HEIGHT}"', 1)
    return (
        f'<mujoco model="panda"><compiler angle="radian" meshdir="{root / "meshes"}"/>'
        f'{assets}<worldbody><body name="base"><body name="torso">{chain}</body></body></worldbody></mujoco>'
    )


def mesh_files() -> list[Path]:
    """Mesh files the robot references, relative to the source meshes folder."""
    files = re.findall(r'file="([^"]+)"', _arm_xml())
    return sorted(Path(f) for f in set(files))


def build_robot_spec(base_xyyaw=(0.0, 0.0, 0.0)) -> mujoco.MjSpec:
    """A fresh MjSpec holding only the robot (plus nothing else); scenes are built on top of it.

    The scene builder starts from this spec and adds the room and objects, because attaching a
    mesh-based model into another spec would have to rewrite the mesh paths.
    """
    import mujoco

    spec = mujoco.MjSpec.from_string(_arm_xml())
    spec.compiler.degree = False
    spec.compiler.autolimits = True
    # The base body sits at the world origin; its joints carry the world pose (base_x = world x,
    # base_y = world y, base_yaw about z), so joint values read directly as the base pose.
    # ``base_xyyaw`` is applied by ``set_home`` (scenes store it in their "init" keyframe).
    base = spec.body("base")
    base.gravcomp = 1.0
    base.add_joint(
        name="base_x", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1, 0, 0], damping=200.0, armature=1.0
    )
    base.add_joint(
        name="base_y", type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, 1, 0], damping=200.0, armature=1.0
    )
    base.add_joint(
        name="base_yaw", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], damping=100.0, armature=1.0
    )
    base.add_geom(
        name="base_geom",
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[BASE_RADIUS, BASE_HEIGHT / 2 - 0.01, 0],
        pos=[0, 0, BASE_HEIGHT / 2 + 0.005],
        rgba=[0.25, 0.27, 0.3, 1],
        mass=40.0,
    )
    # The torso the arm stands on. The lift moves it kinematically (``set_lift`` edits its model
    # position, as the primitives place the base): a lift joint driven by an actuator gave way by
    # 2 cm under the end-effector weld's forces and changed every Gymnasium env's dynamics.
    torso = spec.body("torso")
    torso.add_geom(
        name="torso_column",
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[0.075, (LIFT_MAX - 0.02) / 2, 0],
        pos=[0, 0, BASE_HEIGHT - (LIFT_MAX - 0.02) / 2],
        rgba=[0.25, 0.27, 0.3, 1],
        mass=0.0,
        contype=0,
        conaffinity=0,
    )
    for body in spec.bodies:
        if body.name.startswith("panda_"):
            body.gravcomp = 1.0
    link7 = spec.body("panda_link7")
    cup = link7.add_body(name="suction", pos=[0, 0, 0.165])
    cup.gravcomp = 1.0
    cup.add_geom(
        name="suction_geom",
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[0.02, 0.015, 0],
        pos=[0, 0, 0.015],
        rgba=[0.15, 0.15, 0.15, 1],
        mass=0.05,
    )
    cup.add_site(name="suction_site", pos=[0, 0, 0.031], size=[0.006, 0, 0], rgba=[1, 0.2, 0.2, 1])
    cup.add_site(name="ee_site", pos=[0, 0, 0.031], size=[0.004, 0, 0], rgba=[0.2, 1, 0.2, 0])
    cup.add_camera(name="wrist", pos=[0.05, 0, 0.0], xyaxes=_wrist_xyaxes(), fovy=65.0)
    # Position actuators: base then arm, in ROBOT_JOINTS order.
    for name, kp, frc in (("base_x", 4000, 1000), ("base_y", 4000, 1000), ("base_yaw", 2000, 500)):
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_position(kp=kp, kv=2 * np.sqrt(kp * 40))
        act.forcerange = [-frc, frc]
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
    for name, (kp, frc) in zip(ARM_JOINTS, _ARM_GAINS, strict=True):
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_position(kp=kp)
        act.forcerange = [-frc, frc]
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        jnt = spec.joint(name)
        act.ctrlrange = list(jnt.range)
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
    # End-effector tracking target for delta-pose control (inactive by default).
    target = spec.worldbody.add_body(name="ee_target", mocap=True, pos=[0, 0, 1])
    target.add_geom(
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        size=[0.01, 0, 0],
        contype=0,
        conaffinity=0,
        rgba=[0, 1, 0, 0.0],
        group=4,
    )
    eq = spec.add_equality(name="ee_track", type=mujoco.mjtEq.mjEQ_WELD, name1="suction", name2="ee_target")
    eq.objtype = mujoco.mjtObj.mjOBJ_BODY
    eq.active = False
    eq.solref = [0.02, 1.0]
    return spec


def _wrist_xyaxes(tilt: float = 0.3) -> list[float]:
    """Wrist camera axes in the cup frame: looking out of the cup (+z), tilted ``tilt`` rad towards
    the cup's +x (away from the base at the home pose), so it sees what lies ahead of the cup."""
    look = np.array([np.sin(tilt), 0.0, np.cos(tilt)])
    right = np.cross(look, [0.0, 0.0, -1.0])
    if np.linalg.norm(right) < 1e-6:
        right = np.array([0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, look)
    return [*right.tolist(), *up.tolist()]


def add_suction_welds(spec: mujoco.MjSpec, object_bodies: list[str], held_bodies: list[str] | None = None) -> None:
    """One inactive weld per free object body, so suction is a toggle at run time (no recompiles).

    The weld is named after the object (``suction__<object>``) but may hold another body of it
    (``held_bodies``): the body that carries the mass. MuJoCo softens a weld by the inverse weight of
    the bodies it joins, and an object's massless wrapper body has an enormous one, which left a
    paper ball trailing 30 cm under the cup.
    """
    import mujoco

    for body, held in zip(object_bodies, held_bodies or object_bodies, strict=True):
        eq = spec.add_equality(
            name=SUCTION_PREFIX + body, type=mujoco.mjtEq.mjEQ_WELD, name1="suction", name2=held
        )
        eq.objtype = mujoco.mjtObj.mjOBJ_BODY
        eq.active = False
        eq.solref = [0.01, 1.0]


def set_home(model: mujoco.MjModel, data: mujoco.MjData, base_xyyaw=None) -> None:
    """Put the robot at its home pose (arm) and a base pose; controls hold that pose."""
    for name, value in zip(ARM_JOINTS, HOME_ARM, strict=True):
        data.joint(name).qpos[0] = value
        data.actuator(name).ctrl[0] = value
    if base_xyyaw is not None:
        for name, value in zip(BASE_JOINTS, base_xyyaw, strict=True):
            data.joint(name).qpos[0] = value
    set_lift(model, data, 0.0)
    for name in BASE_JOINTS:
        data.actuator(name).ctrl[0] = data.joint(name).qpos[0]


def lift(model: mujoco.MjModel) -> float:
    """How far the torso lift has raised the arm (metres)."""
    return float(model.body("torso").pos[2])


def set_lift(model: mujoco.MjModel, data: mujoco.MjData, value: float) -> float:
    """Raise the arm by ``value`` (clipped to 0..LIFT_MAX) and update the kinematics; returns the value.

    Kinematic, like the primitives' base placement: the lift is set between motions, never while the
    arm pushes on something. It lives in the model, so it applies to every MjData of that model."""
    import mujoco

    value = float(np.clip(value, 0.0, LIFT_MAX))
    model.body("torso").pos[2] = value
    mujoco.mj_kinematics(model, data)
    return value


def enable_ee_tracking(model: mujoco.MjModel, data: mujoco.MjData) -> int:
    """Switch to end-effector control: the cup follows mocap body ``ee_target`` through the
    ``ee_track`` weld; arm actuators go limp (zero gains) while the base actuators keep holding the
    base where its ``ctrl`` says. The target starts at the cup's current pose. Returns the mocap id.
    """
    import mujoco

    for name in ARM_JOINTS:
        a = model.actuator(name).id
        model.actuator_gainprm[a, :] = 0.0
        model.actuator_biasprm[a, :] = 0.0
    eq = model.equality("ee_track").id
    model.eq_data[eq, :] = 0.0
    model.eq_data[eq, 6] = 1.0
    model.eq_data[eq, 10] = 1.0
    mocap = int(model.body_mocapid[model.body("ee_target").id])
    mujoco.mj_kinematics(model, data)
    cup = model.body("suction").id
    data.mocap_pos[mocap] = data.xpos[cup]
    data.mocap_quat[mocap] = data.xquat[cup]
    for name in BASE_JOINTS:
        data.actuator(name).ctrl[0] = data.joint(name).qpos[0]
    data.eq_active[eq] = 1
    return mocap


def robot_geom_ids(model: mujoco.MjModel) -> np.ndarray:
    """Geoms that belong to the robot (base, arm, cup), for contact filtering."""
    import mujoco

    ids = []
    for g in range(model.ngeom):
        body = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, model.geom_bodyid[g]) or ""
        if body.startswith(ROBOT_BODY_PREFIXES):
            ids.append(g)
    return np.asarray(ids, dtype=int)


def _suction_eq(model: mujoco.MjModel, object_body: str) -> int:
    import mujoco

    return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_EQUALITY, SUCTION_PREFIX + object_body)


def suction_candidates(model: mujoco.MjModel) -> list[str]:
    """Object bodies the cup can hold (those with a suction weld)."""
    import mujoco

    out = []
    for e in range(model.neq):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_EQUALITY, e) or ""
        if name.startswith(SUCTION_PREFIX):
            out.append(name[len(SUCTION_PREFIX) :])
    return out


def object_distance_to_cup(model: mujoco.MjModel, data: mujoco.MjData, object_body: str) -> float:
    """Smallest distance between the cup geom and any geom of the object body (negative: overlap)."""
    import mujoco

    cup = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "suction_geom")
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, object_body)
    best = np.inf
    fromto = np.zeros(6)
    for g in np.flatnonzero(_subtree_geoms(model, body)):
        d = mujoco.mj_geomDistance(model, data, cup, int(g), 0.1, fromto)
        best = min(best, d)
    return float(best)


def _subtree_geoms(model: mujoco.MjModel, body: int) -> np.ndarray:
    """Boolean mask of geoms attached to ``body`` or its descendants."""
    mask = np.zeros(model.ngeom, dtype=bool)
    bodies = {body}
    for b in range(body + 1, model.nbody):
        if model.body_parentid[b] in bodies:
            bodies.add(b)
    for g in range(model.ngeom):
        if model.geom_bodyid[g] in bodies:
            mask[g] = True
    return mask


def held_object(model: mujoco.MjModel, data: mujoco.MjData) -> str | None:
    """The object currently welded to the cup, if any."""
    for name in suction_candidates(model):
        if data.eq_active[_suction_eq(model, name)]:
            return name
    return None


def suction_on(model: mujoco.MjModel, data: mujoco.MjData, object_name: str | None = None, *,
               torquescale: float = 1.0) -> bool:
    """Grab ``object_name`` (or the nearest candidate) if it is within SUCTION_RANGE of the cup.

    The weld's relative pose is set to the current one, so the object does not jump. Returns True
    when an object is now held. ``torquescale`` 0 holds the position only: a door or lid held by
    its face may then turn under the cup as it swings.
    """
    import mujoco

    if held_object(model, data) is not None:
        return True
    mujoco.mj_kinematics(model, data)
    names = [object_name] if object_name is not None else suction_candidates(model)
    best, best_d = None, SUCTION_RANGE
    for name in names:
        if _suction_eq(model, name) < 0:
            continue
        d = object_distance_to_cup(model, data, name)
        if d <= best_d:
            best, best_d = name, d
    if best is None:
        return False
    eq = _suction_eq(model, best)
    cup = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "suction")
    obj = int(model.eq_obj2id[eq])  # the body the weld holds (the object's massive body)
    relpos, relquat = relative_pose(data.xpos[cup], data.xquat[cup], data.xpos[obj], data.xquat[obj])
    # Weld data layout: anchor(3) in body2's frame, relpos(3) = where that anchor sits in body1's
    # frame, relquat(4) = orientation of body2 in body1, torquescale(1). A full weld anchors at body2's
    # origin; a position-only hold (torquescale 0) anchors at the cup's centre instead, since a door's
    # frame sits on its hinge, where holding the position would hold nothing.
    anchor = np.zeros(3)
    if torquescale < 1.0:
        anchor = data.xmat[obj].reshape(3, 3).T @ (data.xpos[cup] - data.xpos[obj])
        relpos = np.zeros(3)
    model.eq_data[eq, 0:3] = anchor
    model.eq_data[eq, 3:6] = relpos
    model.eq_data[eq, 6:10] = relquat
    model.eq_data[eq, 10] = torquescale
    data.eq_active[eq] = 1
    return True


def suction_off(model: mujoco.MjModel, data: mujoco.MjData, object_name: str | None = None) -> None:
    """Release the held object (or ``object_name``)."""
    names = [object_name] if object_name is not None else suction_candidates(model)
    for name in names:
        eq = _suction_eq(model, name)
        if eq >= 0:
            data.eq_active[eq] = 0


def relative_pose(pos1, quat1, pos2, quat2) -> tuple[np.ndarray, np.ndarray]:
    """Pose of frame 2 expressed in frame 1."""
    import mujoco

    neg = np.zeros(4)
    mujoco.mju_negQuat(neg, quat1)
    relpos = np.zeros(3)
    mujoco.mju_rotVecQuat(relpos, np.asarray(pos2) - np.asarray(pos1), neg)
    relquat = np.zeros(4)
    mujoco.mju_mulQuat(relquat, neg, np.asarray(quat2, dtype=float))
    return relpos, relquat
