"""Building the robot's MJCF: the Franka Panda arm from ``gymnasium-robotics`` on our mobile base.

Source of the arm: the Franka Panda MJCF and meshes shipped by the ``gymnasium-robotics`` wheel
(``gymnasium_robotics/envs/assets/kitchen_franka/franka_assets/``, MIT; itself modified from
github.com/vikashplus/franka, Apache-2.0). We read its ``assets.xml`` and ``chain.xml`` at build
time rather than copying them, drop the two parallel fingers (our gripper is a suction cup, as in the
paper) and rename joints to plain ``panda_joint1..7``. The element names and the robot at run time
are in :mod:`anomalygen.scene.robot`.
"""

from __future__ import annotations

import re
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from anomalygen.scene.robot import (
    ARM_GAINS,
    ARM_JOINTS,
    BASE_BODY,
    BASE_HEIGHT,
    BASE_RADIUS,
    CUP_BODY,
    CUP_GEOM,
    CUP_SITE,
    EE_SITE,
    EE_TARGET,
    EE_TRACK,
    LIFT_MAX,
    SUCTION_PREFIX,
    TORSO,
)

if TYPE_CHECKING:  # pragma: no cover
    import mujoco




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
        f'{assets}<worldbody><body name="{BASE_BODY}"><body name="{TORSO}">{chain}</body></body></worldbody></mujoco>'
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
    base = spec.body(BASE_BODY)
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
    torso = spec.body(TORSO)
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
    cup = link7.add_body(name=CUP_BODY, pos=[0, 0, 0.165])
    cup.gravcomp = 1.0
    cup.add_geom(
        name=CUP_GEOM,
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[0.02, 0.015, 0],
        pos=[0, 0, 0.015],
        rgba=[0.15, 0.15, 0.15, 1],
        mass=0.05,
    )
    cup.add_site(name=CUP_SITE, pos=[0, 0, 0.031], size=[0.006, 0, 0], rgba=[1, 0.2, 0.2, 1])
    cup.add_site(name=EE_SITE, pos=[0, 0, 0.031], size=[0.004, 0, 0], rgba=[0.2, 1, 0.2, 0])
    cup.add_camera(name="wrist", pos=[0.05, 0, 0.0], xyaxes=_wrist_xyaxes(), fovy=65.0)
    # Position actuators: base then arm, in ROBOT_JOINTS order.
    for name, kp, frc in (("base_x", 4000, 1000), ("base_y", 4000, 1000), ("base_yaw", 2000, 500)):
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_position(kp=kp, kv=2 * np.sqrt(kp * 40))
        act.forcerange = [-frc, frc]
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
    for name, (kp, frc) in zip(ARM_JOINTS, ARM_GAINS, strict=True):
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_position(kp=kp)
        act.forcerange = [-frc, frc]
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        jnt = spec.joint(name)
        act.ctrlrange = list(jnt.range)
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
    # End-effector tracking target for delta-pose control (inactive by default).
    target = spec.worldbody.add_body(name=EE_TARGET, mocap=True, pos=[0, 0, 1])
    target.add_geom(
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        size=[0.01, 0, 0],
        contype=0,
        conaffinity=0,
        rgba=[0, 1, 0, 0.0],
        group=4,
    )
    eq = spec.add_equality(name=EE_TRACK, type=mujoco.mjtEq.mjEQ_WELD, name1=CUP_BODY, name2=EE_TARGET)
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
            name=SUCTION_PREFIX + body, type=mujoco.mjtEq.mjEQ_WELD, name1=CUP_BODY, name2=held
        )
        eq.objtype = mujoco.mjtObj.mjOBJ_BODY
        eq.active = False
        eq.solref = [0.01, 1.0]
