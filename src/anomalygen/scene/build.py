"""From a TaskProposal to a physically valid MuJoCo scene in which the hazard really exists.

This module runs the attempts and writes the outputs; each step has a module of its own. Pipeline of
one attempt (all randomness from ``item_rng(seed, task.id, attempt)``):

1. select assets (casting.py, with asset_choice.py for each asset): hazard, target, the object the hazard
   sits in/on, the container of the fix, task co-objects, unrelated clutter; sizes from the knowledge
   base, clamped by spatial rules; initial joint states that make the hazard real;
2. place them (placement.py on layout.py; instances.py for holders' surfaces and cavities;
   judgement.py for near-misses, a second hazard and hazard-free scenes) and move the robot base
   within reach; bind the role variables to instance names (casting.py);
3. compose one MjSpec (compose.py: robot + room + objects), compile, reject initial interpenetration;
4. settle the physics for ``settings.build.settle_s``;
5. validate (validate.py): interpenetration <= 1 mm, velocities settled, and the hazard class's
   preconditions hold on the scene graph of the settled state.

A failed attempt is repaired by re-sampling (``settings.build.repair_attempts`` times); then the item
fails with the last one-line reason. Outputs are written only for a valid scene.
"""

from __future__ import annotations

import logging
import os
import shutil
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from anomalygen.assets.real.files import relocate_meshes
from anomalygen.errors import ItemFailed
from anomalygen.knowledge import load_kb
from anomalygen.rng import item_rng, stable_hash
from anomalygen.robot.agent import Agent
from anomalygen.runfolder import atomic_write_bytes, atomic_write_text, write_model
from anomalygen.scene import viewpoint
from anomalygen.scene.casting import bind_roles, select_objects, set_initial_joints
from anomalygen.scene.compose import compose_scene, hold_gravity_hinges, latch_switched_on, set_joints
from anomalygen.scene.instances import renumber_by_position
from anomalygen.scene.judgement import check_hazard_free
from anomalygen.scene.layout import Layout, Placed
from anomalygen.scene.placement import place
from anomalygen.scene.set_states import arrange_states
from anomalygen.scene_files import SCENE_GRAPH, SCENE_SPEC, SCENE_XML, TRUTH, render_file
from anomalygen.schema import (
    AssetRef,
    AssetSource,
    JointState,
    PlacedObject,
    SceneSpec,
    TaskProposal,
    ValidationCheck,
    ValidationReport,
    part_labels,
)
from anomalygen.world.cavities import placed_cavities

if TYPE_CHECKING:
    from anomalygen.config import Settings

log = logging.getLogger(__name__)
CAMERAS = ("front", "top", "wrist")


@dataclass
class Built:
    """A compiled, settled scene in memory (what the outputs are written from)."""

    spec: SceneSpec
    mjspec: object
    model: object
    data: object
    report: ValidationReport
    graph: object
    intents: dict = field(default_factory=dict)  # instance -> truth.manifest.Intent of the judgement mix
    views: list = field(default_factory=list)  # the front camera's candidate views (viewpoint.front_views)


def _plan(task: TaskProposal, settings: Settings, rng, hints=None,
          hazard_free: bool = False, attempt: int = 0) -> tuple[Layout, dict[str, str], dict[str, Placed]]:
    """Choose and place every object; returns the layout, bindings and instances by name.

    A hazard-free scene has no bindings: there is nothing to fix, and the oracle plans nothing."""
    sel = select_objects(task, rng, hints, real_assets=settings.build.real_assets, repair=attempt)
    sel.hazard_free = hazard_free
    set_initial_joints(sel)
    lay, placed, support = place(sel, settings)
    arrange_states(sel, lay, placed)
    _name_as_called(task, sel, placed)
    placed, bindings = renumber_by_position(lay, placed, {} if hazard_free else bind_roles(sel, support))
    return lay, bindings, placed


def _name_as_called(task: TaskProposal, sel, placed: dict[str, Placed]) -> None:
    """The instance chosen for a catalogue name the user called otherwise keeps the user's name: an
    "oven cleaner" built from the cleaning spray's shape is shown, perceived and reported as oven
    cleaner. A name the scene does not hold fails the item rather than being dropped."""
    from anomalygen.errors import ItemFailed
    from anomalygen.scene.asset_choice import resolve_name

    for name, words in task.scenario.called.items():
        ch = sel.by_catalogue.get(resolve_name(name))
        if ch is None or ch.name not in placed:
            raise ItemFailed(f"the task calls {name} '{words}', but the scene holds no {name}")
        placed[ch.name].called = words


# ============================================================================ attempt


def _attempt(task: TaskProposal, seed: int, settings: Settings, attempt: int, hints=None,
             hazard_free: bool = False) -> Built:
    import mujoco

    from anomalygen.scene import validate as val
    from anomalygen.world.graph import scene_graph

    rng = item_rng(seed, task.id, attempt)
    hints = hints.model_copy(deep=True) if hints is not None else None  # each attempt records its own
    lay, bindings, placed = _plan(task, settings, rng, hints, hazard_free, attempt)
    notes = _hint_notes(hints, lay)
    mjspec, views = compose_scene(lay, placed, settings, rng)
    model = mjspec.compile()
    data = mujoco.MjData(model)
    hold_gravity_hinges(model, placed, mjspec)
    latch_switched_on(model, placed, mjspec)
    Agent(model).set_home(data, tuple(lay.base))
    set_joints(model, data, placed)
    mujoco.mj_forward(model, data)
    spec = _scene_spec(task, seed, lay, placed, bindings, model, data)
    overlap = val.initial_overlap(model, data, spec)
    if overlap is not None:
        report = ValidationReport(ok=False, reason=overlap, checks=notes)
        return Built(spec, mjspec, model, data, report, None, views=views)
    nsteps = max(1, int(round(settings.build.settle_s / model.opt.timestep)))
    mujoco.mj_step(model, data, nstep=nsteps)
    if val.max_loose_speed(model, data, placed) > val.MAX_LIN_VEL:
        mujoco.mj_step(model, data, nstep=nsteps)  # something still rolls: give it one more settle
    mujoco.mj_forward(model, data)
    spec = _scene_spec(task, seed, lay, placed, bindings, model, data)
    graph = scene_graph(model, data, spec)
    hc = load_kb().hazard_classes.get(task.hazard_class)
    if hc is not None and not hazard_free:  # a composed class's other objects (the lit burner) by matching
        from anomalygen.knowledge.predicates import bind_others

        spec = spec.model_copy(update={"bindings": bind_others(hc, graph, spec.bindings)})
    report = val.validate(model, data, spec, graph, None if hazard_free else hc)
    if task.source == "user_text" and not hazard_free and report.ok:
        report = val.with_stated_checks(report, task, spec, graph)
    if hazard_free and report.ok:
        report = check_hazard_free(report, graph, task.hazard_class)
    report.checks = notes + report.checks
    return Built(spec, mjspec, model, data, report, graph, {p.name: p.intent for p in placed.values() if p.intent},
                 views)


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
                    label=part_labels.canonical(j.label),
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
        cavities = placed_cavities(model, p.name, p.asset) if p.asset is not None else []
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
                states=_states(ref.category, p.states),
                cavities=cavities,
                called=p.called,
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


def _states(category: str, built: list[str]) -> list[str]:
    """What an instance shows beyond its joints: its kind's own states from the knowledge base and
    those the builder set up for the task (``scene/set_states.py``: water in a basin, a wet floor)."""
    info = load_kb().objects.get(category)
    return list(dict.fromkeys([*(info.states if info else []), *built]))


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
    from anomalygen.scene.verify import verify_with_vlm
    from anomalygen.world.render import SceneRenderer, png_bytes

    with SceneRenderer(built.model, settings.build.render_width, settings.build.render_height) as r:
        png = png_bytes(r.render(built.data, "front"))
    verify_with_vlm(task, built.spec, png, settings)
    built.report.checks.append(
        ValidationCheck(name="vlm_verification", passed=True, detail=settings.llm.model or "")
    )


def write_outputs(built: Built, settings: Settings, out_dir: Path, *, hazard_class: str | None = None) -> SceneSpec:
    """scene.xml, renders, scene_graph.json, the hidden truth.json, scene.json last.

    ``hazard_class`` is the hazard the builder set up (None for a hazard-free scene)."""
    from anomalygen.truth.manifest import hazard_manifest
    from anomalygen.world.render import SceneRenderer, png_bytes

    out_dir.mkdir(parents=True, exist_ok=True)
    model, data, mjspec = built.model, built.data, built.mjspec
    key = mjspec.key("init")
    key.qpos = data.qpos.copy()
    key.qvel = np.zeros(model.nv)
    key.ctrl = data.ctrl.copy()
    if model.nmocap:
        key.mpos = data.mocap_pos.flatten().copy()
        key.mquat = data.mocap_quat.flatten().copy()
    files = {"xml": SCENE_XML, "spec": SCENE_SPEC, "graph": SCENE_GRAPH}
    with SceneRenderer(model, settings.build.render_width, settings.build.render_height) as r:
        if built.views:
            view, worst = viewpoint.choose_front_view(r, model, data, mjspec, [o.name for o in built.spec.objects],
                                                      built.views)
            built.report.checks.append(ValidationCheck(
                name="front_view", passed=True, value=round(worst, 4),
                detail=f"view {view} of {len(built.views)}: the robot covers at most {worst:.0%} of any object"))
        fault = at_fault(built.spec.bindings)
        if fault is not None:  # the answer key stays on the builder's side: scene.json's report
            built.report.checks.extend(viewpoint.fault_coverage(r, model, data, fault))
        _write_xml(mjspec, out_dir)  # after the front view is chosen
        for cam in CAMERAS:
            atomic_write_bytes(out_dir / render_file(cam), png_bytes(r.render(data, cam)))
            files[f"render_{cam}"] = render_file(cam)
    spec = built.spec.model_copy(update={"validation": built.report, "files": files})
    write_model(out_dir / SCENE_GRAPH, built.graph)
    write_model(out_dir / TRUTH, hazard_manifest(spec, hazard_class, built.graph, load_kb(), built.intents))
    write_model(out_dir / SCENE_SPEC, spec)  # last: its presence marks the scene done
    return spec


def at_fault(bindings: dict[str, str]) -> str | None:
    """The object at fault: the hazard, else the target (a window left open); None when hazard-free."""
    return bindings.get("$hazard") or bindings.get("$target")


def _write_xml(mjspec, out_dir: Path) -> None:
    """scene.xml with robot meshes under assets/franka (real models' under assets/real), loadable
    from any working directory."""
    src, files = Agent.mesh_files()
    dst = out_dir / "assets" / "franka"
    for rel in files:
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
    xml = relocate_meshes(xml, out_dir, "assets/franka")  # real models' meshes, under assets/real
    atomic_write_text(out_dir / SCENE_XML, xml)
