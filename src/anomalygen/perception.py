"""What the robot perceives of a built scene: the one door through which detect, plan and learn read it.

Why one module: the builder writes the answer key next to the scene (the truth manifest, the role
bindings and object roles in ``scene.json``, the task itself). The robot side must never see them,
or every figure it earns grades itself. Everything the robot side reads about a scene comes from
here: the scene graph (objects, states, relations), the renders, the simulator model, and a copy of
the scene spec with the answer key removed (no bindings, no roles, no task id).
"""

from __future__ import annotations

from pathlib import Path

from anomalygen.runfolder import try_read_model
from anomalygen.schema import ObjectRole, SceneGraph, SceneSpec

UNKNOWN_ROLE = ObjectRole.AUXILIARY  # every object looks alike to the robot: none is labelled "hazard"


def perceived_spec(spec: SceneSpec) -> SceneSpec:
    """The scene spec as the robot may know it: geometry, joints and poses, without the answer key."""
    objects = [o.model_copy(update={"role": UNKNOWN_ROLE}) for o in spec.objects]
    return spec.model_copy(update={"bindings": {}, "task_id": "", "objects": objects})


def load_perceived_spec(scene_dir: str | Path) -> SceneSpec | None:
    spec = try_read_model(Path(scene_dir) / "scene.json", SceneSpec)
    return perceived_spec(spec) if spec is not None else None


def load_scene_graph(scene_dir: str | Path) -> SceneGraph | None:
    return try_read_model(Path(scene_dir) / "scene_graph.json", SceneGraph)
