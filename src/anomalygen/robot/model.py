"""Building the robot's MJCF: the Franka Panda arm from ``gymnasium-robotics`` on our mobile base.

Source of the arm: the Franka Panda MJCF and meshes shipped by the ``gymnasium-robotics`` wheel
(``gymnasium_robotics/envs/assets/kitchen_franka/franka_assets/``, MIT; itself modified from
github.com/vikashplus/franka, Apache-2.0). We read its ``assets.xml`` and ``chain.xml`` at build
time rather than copying them, drop the two parallel fingers (our gripper is a suction cup, as in the
paper) and rename joints to plain ``panda_joint1..7``. The element names, dimensions and the robot
at run time belong to :class:`anomalygen.robot.agent.Agent`, which calls these builders with itself
(``agent``), so this module spells no name of its own.
"""

from __future__ import annotations

import re
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

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


@lru_cache(maxsize=4)
def _arm_xml(base_body: str, torso: str, base_height: float) -> str:
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
    chain = chain.replace('<body name="panda_link0"', f'<body name="panda_link0" pos="0 0 {base_height}"', 1)
    return (
        f'<mujoco model="panda"><compiler angle="radian" meshdir="{root / "meshes"}"/>'
        f'{assets}<worldbody><body name="{base_body}"><body name="{torso}">{chain}</body></body></worldbody></mujoco>'
    )


def mesh_files(agent) -> list[Path]:
    """Mesh files the robot references, relative to the source meshes folder."""
    files = re.findall(r'file="([^"]+)"', _arm_xml(agent.BASE_BODY, agent.TORSO, agent.BASE_HEIGHT))
    return sorted(Path(f) for f in set(files))


def build_spec(agent, base_xyyaw=(0.0, 0.0, 0.0)) -> mujoco.MjSpec:
    """A fresh MjSpec holding only the robot ``agent`` (its class) names; scenes are built on top of it.

    The scene builder starts from this spec and adds the room and objects, because attaching a
    mesh-based model into another spec would have to rewrite the mesh paths.
    """
    import mujoco

    spec = mujoco.MjSpec.from_string(_arm_xml(agent.BASE_BODY, agent.TORSO, agent.BASE_HEIGHT))
    spec.compiler.degree = False
    spec.compiler.autolimits = True
    # The base body sits at the world origin; its joints carry the world pose (base_x = world x,
    # base_y = world y, base_yaw about z), so joint values read directly as the base pose.
    # ``base_xyyaw`` is applied by ``Agent.set_home`` (scenes store it in their "init" keyframe).
    base = spec.body(agent.BASE_BODY)
    base.gravcomp = 1.0
    bx, by, byaw = agent.BASE_JOINTS
    base.add_joint(name=bx, type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[1, 0, 0], damping=200.0, armature=1.0)
    base.add_joint(name=by, type=mujoco.mjtJoint.mjJNT_SLIDE, axis=[0, 1, 0], damping=200.0, armature=1.0)
    base.add_joint(name=byaw, type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1], damping=100.0, armature=1.0)
    base.add_geom(
        name="base_geom",
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[agent.BASE_RADIUS, agent.BASE_HEIGHT / 2 - 0.01, 0],
        pos=[0, 0, agent.BASE_HEIGHT / 2 + 0.005],
        rgba=[0.25, 0.27, 0.3, 1],
        mass=40.0,
    )
    # The torso the arm stands on. The lift moves it kinematically (``Agent.set_lift`` edits its model
    # position, as the primitives place the base): a lift joint driven by an actuator gave way by
    # 2 cm under the end-effector weld's forces and changed every Gymnasium env's dynamics.
    torso = spec.body(agent.TORSO)
    torso.add_geom(
        name="torso_column",
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[0.075, (agent.LIFT_MAX - 0.02) / 2, 0],
        pos=[0, 0, agent.BASE_HEIGHT - (agent.LIFT_MAX - 0.02) / 2],
        rgba=[0.25, 0.27, 0.3, 1],
        mass=0.0,
        contype=0,
        conaffinity=0,
    )
    for body in spec.bodies:
        if body.name.startswith(agent.ARM_LINK_PREFIX):
            body.gravcomp = 1.0
    link7 = spec.body(f"{agent.ARM_LINK_PREFIX}link7")
    cup = link7.add_body(name=agent.CUP_BODY, pos=[0, 0, 0.165])
    cup.gravcomp = 1.0
    cup.add_geom(
        name=agent.CUP_GEOM,
        type=mujoco.mjtGeom.mjGEOM_CYLINDER,
        size=[0.02, 0.015, 0],
        pos=[0, 0, 0.015],
        rgba=[0.15, 0.15, 0.15, 1],
        mass=0.05,
    )
    cup.add_site(name=agent.CUP_SITE, pos=[0, 0, 0.031], size=[0.006, 0, 0], rgba=[1, 0.2, 0.2, 1])
    cup.add_site(name=agent.EE_SITE, pos=[0, 0, 0.031], size=[0.004, 0, 0], rgba=[0.2, 1, 0.2, 0])
    cup.add_camera(name=agent.WRIST_CAMERA, pos=[0.05, 0, 0.0], xyaxes=_wrist_xyaxes(), fovy=65.0)
    # Position actuators: base then arm, in ROBOT_JOINTS order.
    for name, kp, frc in zip(agent.BASE_JOINTS, (4000, 4000, 2000), (1000, 1000, 500), strict=True):
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_position(kp=kp, kv=2 * np.sqrt(kp * 40))
        act.forcerange = [-frc, frc]
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
    for name, (kp, frc) in zip(agent.ARM_JOINTS, agent.ARM_GAINS, strict=True):
        act = spec.add_actuator(name=name, target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_position(kp=kp)
        act.forcerange = [-frc, frc]
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        jnt = spec.joint(name)
        act.ctrlrange = list(jnt.range)
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
    # End-effector tracking target for delta-pose control (inactive by default).
    target = spec.worldbody.add_body(name=agent.EE_TARGET, mocap=True, pos=[0, 0, 1])
    target.add_geom(
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        size=[0.01, 0, 0],
        contype=0,
        conaffinity=0,
        rgba=[0, 1, 0, 0.0],
        group=4,
    )
    eq = spec.add_equality(name=agent.EE_TRACK, type=mujoco.mjtEq.mjEQ_WELD, name1=agent.CUP_BODY, name2=agent.EE_TARGET)
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


def add_suction_welds(agent, spec: mujoco.MjSpec, object_bodies: list[str], held_bodies: list[str] | None = None) -> None:
    """One inactive weld per free object body, so suction is a toggle at run time (no recompiles).

    The weld is named after the object (``suction__<object>``) but may hold another body of it
    (``held_bodies``): the body that carries the mass. MuJoCo softens a weld by the inverse weight of
    the bodies it joins, and an object's massless wrapper body has an enormous one, which left a
    paper ball trailing 30 cm under the cup.
    """
    import mujoco

    for body, held in zip(object_bodies, held_bodies or object_bodies, strict=True):
        eq = spec.add_equality(
            name=agent.SUCTION_PREFIX + body, type=mujoco.mjtEq.mjEQ_WELD, name1=agent.CUP_BODY, name2=held
        )
        eq.objtype = mujoco.mjtObj.mjOBJ_BODY
        eq.active = False
        eq.solref = [0.01, 1.0]
