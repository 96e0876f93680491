"""Scenes built by the scene stage from test tasks, each with its knowledge-base plan (about a second a scene)."""

from __future__ import annotations


def build_with_kb_plans(tasks: dict, root, *, clutter: int) -> dict:
    """{key: (scene folder, SceneSpec, Plan)} for each TaskProposal in ``tasks``, built with seed 0."""
    from anomalygen.config import Settings
    from anomalygen.plan.planner import plan_from_kb
    from anomalygen.scene.build import build_scene

    out = {}
    for key, task in tasks.items():
        spec = build_scene(task, seed=0, settings=Settings(build={"clutter": clutter}), out_dir=root / key)
        out[key] = (root / key, spec, plan_from_kb(task.id, task.hazard_class, dict(spec.bindings), spec=spec))
    return out
