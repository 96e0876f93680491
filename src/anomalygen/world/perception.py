"""What the robot perceives of a built scene: the one door through which detect, plan and learn read it.

Why one module: the builder writes the answer key next to the scene (the truth manifest, the role
bindings, object roles and validation report in ``scene.json``, the task itself in tasks.jsonl). The
robot side must never see them, or every figure it earns grades itself. Everything the robot side
reads about a scene comes from here: the scene graph (objects, states, relations), the renders, the
simulator model, and a copy of the scene spec with the answer key removed: no bindings, no roles
(every object gets the same neutral one), no validation report (its ``precondition:*`` checks name
the hazard object, its ``hazard_free`` check says what was made safe), no task id, and the objects in
name order (the builder's order placed the support and the hazard first).

Optional perception noise for the detectors lives in :mod:`anomalygen.detect.noise`.
"""

from __future__ import annotations

from pathlib import Path

from anomalygen.runfolder import try_read_model
from anomalygen.scene_files import SCENE_GRAPH, SCENE_SPEC
from anomalygen.schema import ObjectRole, SceneGraph, SceneSpec

UNKNOWN_ROLE = ObjectRole.AUXILIARY  # every object looks alike to the robot: none is labelled "hazard"


def perceived_spec(spec: SceneSpec) -> SceneSpec:
    """The scene spec as the robot may know it: geometry, joints and poses, without the answer key."""
    objects = sorted((o.model_copy(update={"role": UNKNOWN_ROLE}) for o in spec.objects), key=lambda o: o.name)
    return spec.model_copy(update={"bindings": {}, "task_id": "", "validation": None, "objects": objects})


def load_perceived_spec(scene_dir: str | Path) -> SceneSpec | None:
    spec = try_read_model(Path(scene_dir) / SCENE_SPEC, SceneSpec)
    return perceived_spec(spec) if spec is not None else None


def load_scene_graph(scene_dir: str | Path) -> SceneGraph | None:
    return try_read_model(Path(scene_dir) / SCENE_GRAPH, SceneGraph)


def load_perceived_scene(scene_dir: str | Path):
    """The simulator at the settled initial state and the perceived spec: (model, data, spec)."""
    from anomalygen.world.graph import load_scene

    model, data, spec = load_scene(scene_dir)
    return model, data, perceived_spec(spec)
