"""From a TaskProposal to a physically valid MuJoCo scene in which the hazard really exists.

Pipeline of one attempt (all randomness from ``item_rng(seed, task.id, attempt)``):

1. select assets (select.py): hazard, target, the object the hazard sits in/on, the container of the
   fix, task co-objects, unrelated clutter; sizes from the knowledge base, clamped by spatial rules;
   initial joint states that make the hazard real;
2. place them (layout.py) and move the robot base within reach;
3. compose one MjSpec (robot + room + objects), compile, reject initial interpenetration;
4. settle the physics for ``settings.build.settle_s``;
5. validate (validate.py): interpenetration <= 1 mm, velocities settled, and the hazard class's
   preconditions hold on the scene graph of the settled state.

A failed attempt is repaired by re-sampling (``settings.build.repair_attempts`` times); then the item
fails with the last one-line reason. Outputs are written only for a valid scene.
"""

from __future__ import annotations

import logging
import math
import os
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from anomalygen.errors import ItemFailed
from anomalygen.knowledge import load_kb
from anomalygen.rng import item_rng, stable_hash
from anomalygen.runfolder import atomic_write_bytes, atomic_write_text, write_model
from anomalygen.scene import furniture, layout, robot, robot_model, select
from anomalygen.scene.graph import FLOOR_GEOM
from anomalygen.scene.judgement import check_hazard_free
from anomalygen.scene.layout import Layout, Placed
from anomalygen.scene.placement import place
from anomalygen.scene.selection import bind_roles, select_objects, set_initial_joints
from anomalygen.scene.sensors import add_observation_sensors
from anomalygen.schema import (
    AssetRef,
    AssetSource,
    JointState,
    ObjectRole,
    PlacedObject,
    SceneSpec,
    TaskProposal,
    ValidationCheck,
    ValidationReport,
)

if TYPE_CHECKING:
    from anomalygen.config import Settings

log = logging.getLogger(__name__)
CAMERAS = ("front", "top", "wrist")


LOOSE_SOLREF = 0.005  # s: contact time constant of loose objects (2.5 physics steps)


@dataclass
class Built:
    """A compiled, settled scene in memory (what the outputs are written from)."""

    spec: SceneSpec
    mjspec: object
    model: object
    data: object
    report: ValidationReport
    graph: object


# ============================================================================ selection


def _plan(task: TaskProposal, settings: Settings, rng, hints=None,
          hazard_free: bool = False) -> tuple[Layout, dict[str, str], dict[str, Placed]]:
    """Choose and place every object; returns the layout, bindings and instances by name.

    A hazard-free scene has no bindings: there is nothing to fix, and the oracle plans nothing."""
    sel = select_objects(task, rng, hints)
    sel.hazard_free = hazard_free
    set_initial_joints(sel)
    lay, placed, support = place(sel, settings)
    return lay, ({} if hazard_free else bind_roles(sel, support)), placed


# ============================================================================ composition


def _look_at_xyaxes(eye, target) -> list[float]:
    """Camera xyaxes (MuJoCo cameras look along -z) for a camera at ``eye`` looking at ``target``."""
    fwd = np.asarray(target, float) - np.asarray(eye, float)
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, [0.0, 0.0, 1.0])
    if np.linalg.norm(right) < 1e-6:
        right = np.array([0.0, -1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    return [*right.tolist(), *up.tolist()]


def _compose(lay: Layout, placed: dict[str, Placed], settings: Settings, rng):
    import mujoco

    spec = robot_model.build_robot_spec(tuple(lay.base))
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
    mat = spec.add_material(name="floor_mat", texrepeat=[6, 6], reflectance=0.05)
    mat.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = tex.name
    center = layout.ROOM_CENTER
    half = layout.ROOM_HALF + 0.6
    spec.worldbody.add_geom(
        name=FLOOR_GEOM,
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[half[0], half[1], 0.05],
        pos=[center[0], center[1], 0],
        material="floor_mat",
    )
    wall_rgba = [0.86, 0.85, 0.8, 1]
    spec.worldbody.add_geom(
        name="wall_back",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[0.05, half[1], 1.3],
        pos=[center[0] + half[0] + 0.05, center[1], 1.3],
        rgba=wall_rgba,
    )
    spec.worldbody.add_geom(
        name="wall_left",
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[half[0], 0.05, 1.3],
        pos=[center[0], center[1] + half[1] + 0.05, 1.3],
        rgba=wall_rgba,
    )
    spec.worldbody.add_light(
        name="sun",
        pos=[center[0], center[1], 3.5],
        dir=[0.2, 0.1, -1],
        type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL,
        diffuse=[0.6, 0.6, 0.6],
        specular=[0.1, 0.1, 0.1],
        castshadow=True,
    )
    spec.worldbody.add_light(
        name="fill", pos=[-1.0, -1.0, 2.5], dir=[0.5, 0.4, -0.6], diffuse=[0.35, 0.35, 0.35], castshadow=False
    )

    focus = np.mean(
        [p.world_center() for p in placed.values() if p.role != ObjectRole.CLUTTER]
        or [np.array([1.0, 0, 0.4])],
        axis=0,
    )
    focus[2] = min(max(focus[2], 0.2), 0.8)
    # Front camera: behind the robot as seen from the task objects, raised, turned 30 degrees, so
    # the robot stands in the foreground and the scene behind it.
    away = lay.base[:2] - focus[:2]
    dist = float(np.linalg.norm(away))
    away = away / dist if dist > 1e-6 else np.array([-1.0, 0.0])
    c, s = math.cos(0.5), math.sin(0.5)
    away = np.array([c * away[0] - s * away[1], s * away[0] + c * away[1]])
    eye = np.r_[focus[:2] + away * (dist + 1.0), 1.9]
    spec.worldbody.add_camera(name="front", pos=eye.tolist(), xyaxes=_look_at_xyaxes(eye, focus), fovy=60)
    top_eye = np.array([focus[0], focus[1] - 0.01, 3.3])
    spec.worldbody.add_camera(name="top", pos=top_eye.tolist(), xyaxes=[0, -1, 0, 1, 0, 0], fovy=55)

    loose, parts = [], []
    for p in placed.values():
        body = spec.worldbody.add_body(name=p.name, pos=p.pos.tolist(), quat=p.quat)
        if p.support_geom is not None:
            furniture.emit(p.support_geom, body, rng)
            continue
        root = p.asset.attach(body, f"{p.name}/")
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
            for geom in _geoms_below(root):
                geom.condim = 6
                geom.friction = [max(geom.friction[0], 0.8), 0.01, 0.002]
                geom.margin = max(geom.margin, 0.001)
                geom.priority = 1
                geom.solref = [LOOSE_SOLREF, 1.0]
    # Suction can also hold a door, lid or drawer, so primitives can pull parts open or lift them shut.
    robot_model.add_suction_welds(spec, [n for n, _ in loose] + parts, [r for _, r in loose] + parts)
    task_objects = [p for p in placed.values() if p.role != ObjectRole.CLUTTER]
    add_observation_sensors(
        spec,
        list(robot.ROBOT_JOINTS),
        [p.name for p in task_objects],
        [f"{p.name}/{j.name}" for p in task_objects if p.asset is not None for j in p.asset.joints],
    )
    spec.add_key(name="init")
    return spec


def _articulated_bodies(body) -> list[str]:
    """Names of the bodies under ``body`` that move on a hinge or slide joint (doors, lids, drawers)."""
    import mujoco

    out = []
    if any(j.type in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE) for j in body.joints):
        out.append(body.name)
    for child in body.bodies:
        out.extend(_articulated_bodies(child))
    return out


def _geoms_below(body) -> list:
    out = list(body.geoms)
    for child in body.bodies:
        out.extend(_geoms_below(child))
    return out


def _latch_switched_on(model, placed: dict[str, Placed], mjspec) -> None:
    """A spring-returned button set to 'on' is modelled as latched (a kettle's switch stays down):
    its return spring is removed so the hazard state persists; friction keeps it where it is set."""
    import mujoco

    for p in placed.values():
        if p.asset is None:
            continue
        for j in p.asset.joints:
            value = p.joint_values.get(j.name)
            if value is None or abs(value - j.closed_value) < 1e-9:
                continue
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f"{p.name}/{j.name}")
            if jid < 0 or model.jnt_stiffness[jid] <= 0:
                continue
            stiffness = float(model.jnt_stiffness[jid])
            model.jnt_stiffness[jid] = 0.0
            dof = model.jnt_dofadr[jid]
            hold = stiffness * abs(value - j.closed_value) * 1.5
            model.dof_frictionloss[dof] = max(model.dof_frictionloss[dof], hold)
            sj = mjspec.joint(f"{p.name}/{j.name}")
            sj.stiffness = [0.0] * len(sj.stiffness) if hasattr(sj.stiffness, "__len__") else 0.0
            sj.frictionloss = float(model.dof_frictionloss[dof])


def _hold_gravity_hinges(model, placed: dict[str, Placed], mjspec) -> None:
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


def _set_joints(model, data, placed: dict[str, Placed]) -> None:
    for p in placed.values():
        for jname, value in p.joint_values.items():
            data.joint(f"{p.name}/{jname}").qpos[0] = value


# ============================================================================ attempt


def _attempt(task: TaskProposal, seed: int, settings: Settings, attempt: int, hints=None,
             hazard_free: bool = False) -> Built:
    import mujoco

    from anomalygen.scene import validate as val
    from anomalygen.scene.graph import scene_graph

    rng = item_rng(seed, task.id, attempt)
    hints = hints.model_copy(deep=True) if hints is not None else None  # each attempt records its own
    lay, bindings, placed = _plan(task, settings, rng, hints, hazard_free)
    notes = _hint_notes(hints, lay)
    mjspec = _compose(lay, placed, settings, rng)
    model = mjspec.compile()
    data = mujoco.MjData(model)
    _hold_gravity_hinges(model, placed, mjspec)
    _latch_switched_on(model, placed, mjspec)
    robot.set_home(model, data, tuple(lay.base))
    _set_joints(model, data, placed)
    mujoco.mj_forward(model, data)
    spec = _scene_spec(task, seed, lay, placed, bindings, model, data)
    overlap = val.initial_overlap(model, data, spec)
    if overlap is not None:
        report = ValidationReport(ok=False, reason=overlap, checks=notes)
        return Built(spec, mjspec, model, data, report, None)
    nsteps = max(1, int(round(settings.build.settle_s / model.opt.timestep)))
    mujoco.mj_step(model, data, nstep=nsteps)
    if val.max_loose_speed(model, data, placed) > val.MAX_LIN_VEL:
        mujoco.mj_step(model, data, nstep=nsteps)  # something still rolls: give it one more settle
    mujoco.mj_forward(model, data)
    spec = _scene_spec(task, seed, lay, placed, bindings, model, data)
    graph = scene_graph(model, data, spec)
    hc = load_kb().hazard_classes.get(task.hazard_class)
    report = val.validate(model, data, spec, graph, None if hazard_free else hc)
    if hazard_free and report.ok:
        report = check_hazard_free(report, graph, task.hazard_class)
    report.checks = notes + report.checks
    return Built(spec, mjspec, model, data, report, graph)


def _hint_notes(hints, lay: Layout) -> list[ValidationCheck]:
    """Every correction to an engine's sizes and positions, for the validation report (none offline)."""
    if hints is None:
        return []
    done = {c.name for c in lay.corrections}
    notes = list(hints.checks) + list(lay.corrections)
    notes += [
        ValidationCheck(name=f"position:{name}", passed=True, detail="placed by its scenario placement (on or in "
                        "another object), not at the proposed floor spot")
        for name in lay.preferred if f"position:{name}" not in done
    ]
    return notes


def _scene_spec(task, seed, lay: Layout, placed: dict[str, Placed], bindings, model, data) -> SceneSpec:
    objects = []
    for p in placed.values():
        body = data.body(p.name)
        if p.asset is not None:
            ref = p.asset.ref
            size = float(p.asset.size)
            joints = [
                JointState(
                    name=f"{p.name}/{j.name}",
                    label=select.kb_label(j.label),
                    type=j.type,
                    value=float(data.joint(f"{p.name}/{j.name}").qpos[0]),
                    range=(float(j.range[0]), float(j.range[1])),
                    closed_value=float(j.closed_value),
                )
                for j in p.asset.joints
            ]
        else:
            s = p.support_geom
            ref = AssetRef(
                asset_id=f"support-{s.kind}-{s.top:.3f}",
                category=s.category,
                source=AssetSource.PROCEDURAL,
                params={"kind": s.kind, "half": list(s.half), "top": s.top, "thickness": s.thickness},
            )
            size = s.size
            joints = []
        objects.append(
            PlacedObject(
                name=p.name,
                asset=ref,
                role=p.role,
                size=size,
                pos=[float(v) for v in body.xpos],
                quat=[float(v) for v in body.xquat],
                support=p.support,
                inside=p.inside,
                joint_states=joints,
                fixed=p.fixed,
            )
        )
    return SceneSpec(
        scene_id=scene_id_for(task.id),
        task_id=task.id,
        room=task.scenario.room,
        seed=seed,
        objects=objects,
        robot_base=[float(v) for v in lay.base],
        bindings=bindings,
    )


def scene_id_for(task_id: str) -> str:
    """An opaque scene id: task ids may carry words of the task, which detection must not see."""
    return f"scene_{stable_hash('scene', task_id) & 0xFFFFFFFFFF:010x}"


# ============================================================================ public entry


def build_scene(task: TaskProposal, *, seed: int, settings: Settings, out_dir: Path, hints=None,
                hazard_free: bool = False) -> SceneSpec:
    """Build, settle, validate, repair and write one scene; raises ItemFailed with a one-line reason.

    ``hazard_free`` builds the task's object in its safe state (``scene/mix.py``); its truth.json then
    lists only what the settled scene really shows.

    ``hints`` come from a non-default scene engine (``scene/llm_engine.py``); None keeps the draws."""
    attempts = settings.build.repair_attempts + 1
    reason = "no attempt made"
    built = None
    for attempt in range(attempts):
        try:
            built = _attempt(task, seed, settings, attempt, hints, hazard_free)
        except ItemFailed as exc:
            reason = str(exc)
            log.debug("%s attempt %d: %s", task.id, attempt, reason)
            continue
        if built.report.ok and settings.llm.configured and settings.llm.vision:
            try:
                _vlm_check(task, built, settings)
            except ItemFailed as exc:
                built.report.ok = False
                built.report.reason = str(exc)
        if built.report.ok:
            built.report.repairs = attempt
            break
        reason = built.report.reason
        log.debug("%s attempt %d: %s", task.id, attempt, reason)
        built = None
    if built is None:
        raise ItemFailed(f"no valid scene after {attempts} attempt(s): {reason}")
    return write_outputs(built, settings, Path(out_dir), hazard_class=None if hazard_free else task.hazard_class)


def _vlm_check(task, built: Built, settings: Settings) -> None:
    from anomalygen.scene.render import SceneRenderer, png_bytes
    from anomalygen.scene.verify import verify_with_vlm

    with SceneRenderer(built.model, settings.build.render_width, settings.build.render_height) as r:
        png = png_bytes(r.render(built.data, "front"))
    verify_with_vlm(task, built.spec, png, settings)
    built.report.checks.append(
        ValidationCheck(name="vlm_verification", passed=True, detail=settings.llm.model or "")
    )


def write_outputs(built: Built, settings: Settings, out_dir: Path, *, hazard_class: str | None = None) -> SceneSpec:
    """scene.xml, renders, scene_graph.json, the hidden truth.json, scene.json last.

    ``hazard_class`` is the hazard the builder set up (None for a hazard-free scene)."""
    from anomalygen.scene.render import SceneRenderer, png_bytes
    from anomalygen.scene.truth import TRUTH_FILE, hazard_manifest

    out_dir.mkdir(parents=True, exist_ok=True)
    model, data, mjspec = built.model, built.data, built.mjspec
    key = mjspec.key("init")
    key.qpos = data.qpos.copy()
    key.qvel = np.zeros(model.nv)
    key.ctrl = data.ctrl.copy()
    if model.nmocap:
        key.mpos = data.mocap_pos.flatten().copy()
        key.mquat = data.mocap_quat.flatten().copy()
    files = {"xml": "scene.xml", "spec": "scene.json", "graph": "scene_graph.json"}
    _write_xml(mjspec, out_dir)
    with SceneRenderer(model, settings.build.render_width, settings.build.render_height) as r:
        for cam in CAMERAS:
            atomic_write_bytes(out_dir / f"render_{cam}.png", png_bytes(r.render(data, cam)))
            files[f"render_{cam}"] = f"render_{cam}.png"
    spec = built.spec.model_copy(update={"validation": built.report, "files": files})
    write_model(out_dir / "scene_graph.json", built.graph)
    write_model(out_dir / TRUTH_FILE, hazard_manifest(spec, hazard_class, built.graph, load_kb()))
    write_model(out_dir / "scene.json", spec)  # last: its presence marks the scene done
    return spec


def _write_xml(mjspec, out_dir: Path) -> None:
    """scene.xml with robot meshes under assets/franka, loadable from any working directory."""
    src = robot_model.franka_assets_dir() / "meshes"
    dst = out_dir / "assets" / "franka"
    for rel in robot_model.mesh_files():
        target = dst / rel
        if target.exists():
            continue
        target.parent.mkdir(parents=True, exist_ok=True)
        try:
            os.link(src / rel, target)  # hard link: no copy of the 6 MB of meshes per scene
        except OSError:
            shutil.copyfile(src / rel, target)
    xml = mjspec.to_xml()
    xml = xml.replace(f'meshdir="{src}"', 'meshdir="assets/franka"', 1)
    if 'meshdir="assets/franka"' not in xml:  # pragma: no cover - MuJoCo changed its XML writer
        raise RuntimeError("could not relocate the robot mesh folder in scene.xml")
    atomic_write_text(out_dir / "scene.xml", xml)
