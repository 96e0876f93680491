"""One MjSpec from a placed layout: robot, room, cameras, lights and objects; joint tuning after compile.

Loose objects get rolling friction and stiff contacts; after compiling, hinges that gravity would
swing shut get friction and a button set to 'on' is latched, so the hazard state survives settling.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from anomalygen.mjgeom import FLOOR_GEOM
from anomalygen.robot.agent import Agent
from anomalygen.scene import furniture, viewpoint, walls
from anomalygen.scene.layout import Layout, Placed
from anomalygen.scene.viewpoint import CAMERA_FOVY, FRAME_TOP
from anomalygen.schema import part_labels
from anomalygen.world.room import ROOM_CENTER
from anomalygen.world.sensors import add_observation_sensors
from anomalygen.world.states import geoms_below, show_states

if TYPE_CHECKING:
    from anomalygen.config import Settings


LOOSE_SOLREF = 0.005  # s: contact time constant of loose objects (2.5 physics steps)
FLOOR_TILE = 1.6  # m: one repeat of the floor's checker texture (two tiles)
WALL_ABOVE_EYE = 0.3  # m: walls rise this far above the highest front view, so no view sees over them


def wall_openings(placed) -> list[walls.Opening]:
    """The holes the walls need behind the windows and doors mounted in them."""
    out = []
    for p in placed:
        if walls.mount_height(p.catalogue) is None:
            continue
        lo, hi = p.footprint()
        side = walls.wall_of(lo, hi)
        if side is not None:
            out.append(walls.opening_for(side, lo, hi, p.catalogue))
    return out


def compose_scene(lay: Layout, placed: dict[str, Placed], settings: Settings, rng):
    import mujoco

    spec = Agent.build_spec(tuple(lay.base))
    spec.modelname = "anomalygen_scene"
    spec.option.timestep = 0.002
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.visual.global_.offwidth = max(640, settings.build.render_width)
    spec.visual.global_.offheight = max(480, settings.build.render_height)
    spec.visual.quality.shadowsize = 512
    tex = spec.add_texture(
        name="floor_tex",
        type=mujoco.mjtTexture.mjTEXTURE_2D,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
        rgb1=[0.62, 0.58, 0.52],
        rgb2=[0.55, 0.5, 0.45],
        width=256,
        height=256,
    )
    mat = spec.add_material(name="floor_mat", texrepeat=[walls.WALL_REACH / FLOOR_TILE] * 2, reflectance=0.05)
    mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = tex.name
    # the floor ends at the walls' faces (through a window one sees the ground outside, not the floor)
    # and runs the other way as far as they do
    half = np.full(2, walls.WALL_REACH / 2)
    center = np.array([walls.WALL_X, walls.WALL_Y]) - half
    spec.worldbody.add_geom(
        name=FLOOR_GEOM,
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[half[0], half[1], 0.05],
        pos=[center[0], center[1], 0],
        material="floor_mat",
    )
    spec.worldbody.add_light(
        name="sun",
        pos=[ROOM_CENTER[0], ROOM_CENTER[1], 3.5],
        dir=[0.2, 0.1, -1],
        type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
        diffuse=[0.6, 0.6, 0.6],
        specular=[0.1, 0.1, 0.1],
        castshadow=True,
    )
    spec.worldbody.add_light(
        name="fill", pos=[-1.0, -1.0, 2.5], dir=[0.5, 0.4, -0.6], diffuse=[0.35, 0.35, 0.35], castshadow=False
    )

    views = add_room_cameras(spec, list(placed.values()), settings.build.render_width / settings.build.render_height)
    walls.emit_walls(spec, wall_openings(placed.values()), max(eye[2] for eye, _ in views) + WALL_ABOVE_EYE)

    objects = sorted(placed.values(), key=lambda p: p.name)  # name order: no role shows in the model
    loose, parts = [], []
    for p in objects:
        body = spec.worldbody.add_body(name=p.name, pos=p.pos.tolist(), quat=p.quat)
        if p.support_geom is not None:
            furniture.emit(p.support_geom, body, rng)
            continue
        root = p.asset.attach(body, f"{p.name}/")
        show_states(root, p)
        if not p.fixed:
            body.add_freejoint(name=f"{p.name}/free")
            loose.append((p.name, root.name))
        parts.extend(_articulated_bodies(root))
        if not p.fixed:
            # Rolling and torsional friction (condim 6): a needle or pencil must not roll for ever.
            # A 1 mm contact margin stops needles and coins tunnelling into a table top. Their
            # contacts are stiffer than the 20 ms default (priority makes theirs win): with it a
            # needle set down in a box sank past the middle of the 8 mm bottom and was pushed out
            # underneath.
            for geom in geoms_below(root):
                geom.condim = 6
                geom.friction = [max(geom.friction[0], 0.8), 0.01, 0.002]
                geom.margin = max(geom.margin, 0.001)
                geom.priority = 1
                geom.solref = [LOOSE_SOLREF, 1.0]
    # Suction can also hold a door, lid or drawer, so primitives can pull parts open or lift them shut.
    Agent.add_suction_welds(spec, [n for n, _ in loose] + parts, [r for _, r in loose] + parts)
    add_observation_sensors(  # every object alike: the sensor list must not tell the task's objects apart
        spec,
        list(Agent.ROBOT_JOINTS),
        [p.name for p in objects],
        [f"{p.name}/{j.name}" for p in objects if p.asset is not None for j in p.asset.joints],
    )
    spec.add_key(name="init")
    return spec, views


def add_room_cameras(spec, objects: list[Placed], aspect: float) -> list:
    """The ``front`` and ``top`` cameras, framed on the furnished part of the room: the box around
    every object's footprint, each object alike, up to ``FRAME_TOP`` high; returns the front camera's
    candidate views (``viewpoint.front_views``; it starts at the first).

    Why not the task's objects: cameras aimed at their mean pointed the robot at the hazard. The
    front camera looks in from the room's open corner at the walls (at +x and +y), just far enough
    back for the box to fit its view (``aspect``: width / height); the top camera looks straight down
    from just high enough."""
    boxes = [p.footprint() for p in objects] or [(np.r_[ROOM_CENTER - 1.0, 0.0], np.r_[ROOM_CENTER + 1.0, 1.0])]
    views = viewpoint.front_views(boxes, aspect)
    eye, xyaxes = views[0]
    spec.worldbody.add_camera(name="front", pos=eye.tolist(), xyaxes=xyaxes, fovy=CAMERA_FOVY)
    # top view: image up is world +x, image right is world -y
    lo, hi = viewpoint.frame_box(boxes)
    tan_v = math.tan(math.radians(CAMERA_FOVY) / 2)
    half = (hi - lo) / 2
    top = max(half[0] / tan_v, half[1] / (tan_v * aspect)) + FRAME_TOP
    top_eye = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2 - 0.01, top])
    spec.worldbody.add_camera(name="top", pos=top_eye.tolist(), xyaxes=[0, -1, 0, 1, 0, 0], fovy=CAMERA_FOVY)
    return views


def _articulated_bodies(body) -> list[str]:
    """Names of the bodies under ``body`` that move on a hinge or slide joint (doors, lids, drawers)."""
    import mujoco

    out = []
    if any(j.type in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE) for j in body.joints):
        out.append(body.name)
    for child in body.bodies:
        out.extend(_articulated_bodies(child))
    return out


def latch_switched_on(model, placed: dict[str, Placed], mjspec) -> None:
    """A spring-returned button set to 'on' is modelled as latched (a kettle's switch stays down):
    its return spring is removed so the hazard state persists; friction keeps it where it is set. The
    latch holds either position, so the part's own weight is compensated too: MuJoCo's friction is a
    soft constraint, and a coffee machine's 6 g top button, switched off, crept back in under gravity
    (on again within 50 steps)."""
    import mujoco

    for p in placed.values():
        if p.asset is None:
            continue
        for j in p.asset.joints:
            value = p.joint_values.get(j.name)
            if value is None or abs(value - j.closed_value) < 1e-9:
                continue
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{p.name}/{j.name}")
            if jid < 0:
                continue
            if model.jnt_stiffness[jid] <= 0:
                _hold_switch_set_on(model, mjspec, p, j, jid)
                continue
            stiffness = float(model.jnt_stiffness[jid])
            model.jnt_stiffness[jid] = 0.0
            dof = model.jnt_dofadr[jid]
            hold = stiffness * abs(value - j.closed_value) * 1.5
            model.dof_frictionloss[dof] = max(model.dof_frictionloss[dof], hold)
            sj = mjspec.joint(f"{p.name}/{j.name}")
            sj.stiffness = [0.0] * len(sj.stiffness) if hasattr(sj.stiffness, "__len__") else 0.0
            sj.frictionloss = float(model.dof_frictionloss[dof])
            _compensate_weight(model, mjspec, int(model.jnt_bodyid[jid]))


def _hold_switch_set_on(model, mjspec, p: Placed, j, jid: int) -> None:
    """A switch with no spring that was set on stays on until something turns it: its weight is
    compensated. A single-lever tap holds any position in its cartridge, but MuJoCo's friction is a
    soft constraint that creeps under a steady load: a bathtub's lever, set 70 % open and held by 1.3x
    its gravity torque, crept shut in 4 s, so a scene where nobody did anything read "resolved".
    Turned off, it rests on its limit as before; only on/off controls are held, never doors or lids."""
    if j.type != "hinge" or not part_labels.is_switch(j.label):
        return
    _compensate_weight(model, mjspec, int(model.jnt_bodyid[jid]))


def _compensate_weight(model, mjspec, body: int) -> None:
    """Gravity compensation on one body, in the compiled model and in the spec it is saved from."""
    model.body_gravcomp[body] = 1.0
    mjspec.body(model.body(body).name).gravcomp = 1.0


def hold_gravity_hinges(model, placed: dict[str, Placed], mjspec) -> None:
    """Give horizontal-axis hinges (lids, laptop screens) enough friction to stay where they are set.

    Real lids and oven doors are stiff enough to stay open; a frictionless model would slam shut
    during settling and the hazard would vanish. The friction is 1.3x the gravity torque of the
    moving part, so the robot can still close it.
    """
    import mujoco

    g = abs(model.opt.gravity[2])
    for p in placed.values():
        if p.asset is None:
            continue
        for j in p.asset.joints:
            vertical_slide = j.type == "slide" and abs(j.axis[2]) > 0.7
            if not vertical_slide and (j.type != "hinge" or abs(j.axis[2]) > 0.7):
                continue
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{p.name}/{j.name}")
            if jid < 0:
                continue
            body = model.jnt_bodyid[jid]
            mass = model.body_subtreemass[body]
            lever = (
                float(np.linalg.norm(model.body_ipos[body]))
                + 0.5 * float(np.max(model.body_inertia[body]) / max(mass, 1e-6)) ** 0.5
            )
            friction = 1.3 * mass * g * (1.0 if vertical_slide else max(lever, 0.02))
            dof = model.jnt_dofadr[jid]
            model.dof_frictionloss[dof] = max(model.dof_frictionloss[dof], friction)
            mjspec.joint(f"{p.name}/{j.name}").frictionloss = float(model.dof_frictionloss[dof])


def set_joints(model, data, placed: dict[str, Placed]) -> None:
    for p in placed.values():
        for jname, value in p.joint_values.items():
            data.joint(f"{p.name}/{jname}").qpos[0] = value
