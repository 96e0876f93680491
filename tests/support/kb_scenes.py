"""Scenes built by the scene stage from test tasks, each with its knowledge-base plan (about a second a scene)."""

from __future__ import annotations

# skill tests run on the classic single-hazard scenes: no near-misses, second hazards or safe variants
NO_MIX = {"near_misses": 0, "multi_hazard": 0.0, "hazard_free": 0.0}
# ... with the robot already standing within reach of the hazard, facing it (``build.start = "reach"``):
# they test the skills, not the first approach from the dock (the learn-stage tests start docked)
SKILL_SCENES = {**NO_MIX, "start": "reach"}


def build_with_kb_plans(tasks: dict, root, *, clutter: int) -> dict:
    """{key: (scene folder, SceneSpec, Plan)} for each TaskProposal in ``tasks``, built with seed 0."""
    from anomalygen.config import Settings
    from anomalygen.plan.planner import plan_from_kb
    from anomalygen.scene.build import build_scene

    out = {}
    for key, task in tasks.items():
        spec = build_scene(task, seed=0, settings=Settings(build={"clutter": clutter, **SKILL_SCENES}), out_dir=root / key)
        out[key] = (root / key, spec, plan_from_kb(task.id, task.hazard_class, dict(spec.bindings), spec=spec))
    return out
