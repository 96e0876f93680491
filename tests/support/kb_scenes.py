"""Scenes built by the scene stage from test tasks, each with its knowledge-base plan (about a second a scene)."""

from __future__ import annotations

# skill tests run on the classic single-hazard scenes: no near-misses, second hazards or safe variants
NO_MIX = {"near_misses": 0, "multi_hazard": 0.0, "hazard_free": 0.0}
# ... with the robot already standing within reach of the hazard, facing it (``build.start = "reach"``):
# they test the skills, not the first approach from the dock (the learn-stage tests start docked)
SKILL_SCENES = {**NO_MIX, "start": "reach"}


def build_with_kb_plans(tasks: dict, root, *, clutter: int, real_assets: bool = True) -> dict:
    """{key: (scene folder, SceneSpec, Plan)} for each TaskProposal in ``tasks``, built with seed 0
    (``real_assets`` False: procedural assets only, as before the real models)."""
    from anomalygen.config import Settings
    from anomalygen.plan.planner import plan_from_kb
    from anomalygen.scene.build import build_scene

    out = {}
    for key, task in tasks.items():
        settings = Settings(build={"clutter": clutter, "real_assets": real_assets, **SKILL_SCENES})
        spec = build_scene(task, seed=0, settings=settings, out_dir=root / key)
        out[key] = (root / key, spec, plan_from_kb(task.id, task.hazard_class, dict(spec.bindings), spec=spec))
    return out


def kb_task(task_id, hazard_class, target, hazard, placement, *, container=None, articulations=(), room="kitchen",
            states=None, co_objects=()):
    """A knowledge-engine TaskProposal for a scene test: ``articulations`` are (object, part, state),
    ``states`` the instance states by catalogue name ({'Stove': ['lit']})."""
    from anomalygen.schema import TaskProposal

    return TaskProposal(
        id=task_id, name=f"task {task_id}", explanation="test", description=f"A {hazard} at {placement}.",
        category="household_hazard", hazard_class=hazard_class, target_asset=target,
        scenario=dict(hazard_object=hazard, room=room, placement=placement, container=container,
                      states=states or {}, co_objects=list(co_objects)),
        articulations=[dict(object=o, part=p, initial_state=s) for o, p, s in articulations],
        provenance=dict(engine="knowledge", mode="brainstorm"))


def state_task(task_id, target, hazard, placement, states=None, *, arts=(), room="kitchen", co=()):
    """A task with no class of its own ('other') that asks for instance states: the open-world objects' tests."""
    return kb_task(task_id, "other", target, hazard, placement, articulations=arts, room=room, states=states,
                   co_objects=co)
