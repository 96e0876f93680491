"""Look again after acting: hazards the robot's own fix created are seen and fixed before it leaves.

Why: a fix is physical. Closing an oven door can nudge a knob on; a drawer the arm opened for access
can jam half open; a bottle that slips from the cup lands on the floor within a child's reach. A
careful person glances back at the scene before walking away, and so does the robot: it reads the
scene graph of the simulator state after the plan (what it perceives, never the truth file), runs the
same rules it detected with, and plans a fix (from the knowledge base, roles bound from perception)
for each hazard that was not there before it started. A hazard on an object the robot moved counts as
new too: a hammer taken down off a shelf's edge and set down at the edge of a low cabinet is a heavy
thing at an edge again, at a new place, although the rules saw "heavy at an edge" on it at the start.
One such pass; what is still wrong after it is left for the referee to count.
"""

from __future__ import annotations

from anomalygen.errors import ItemFailed
from anomalygen.plan.fixes import Fix
from anomalygen.schema import Plan, SceneGraph, SceneSpec


def hazards_seen(graph: SceneGraph, kb) -> dict[tuple[str, str], float]:
    """(object, class) -> severity for every class the rules find on the perceived graph."""
    from anomalygen.detect.rules import candidates

    return {(c.object, c.hazard_class): c.severity for c in candidates(graph, kb)}


MOVED = 0.05  # m an object's centre travels before what fires on it is the robot's doing


def moved_objects(before: SceneGraph, after: SceneGraph) -> set[str]:
    """Objects whose perceived centre moved more than MOVED between the two graphs."""
    import numpy as np

    start = {o.name: np.asarray(o.position) for o in before.objects}
    return {o.name for o in after.objects
            if o.name in start and float(np.linalg.norm(np.asarray(o.position) - start[o.name])) > MOVED}


def new_hazards(before: SceneGraph, after: SceneGraph, kb) -> list[tuple[str, str]]:
    """Hazards on ``after`` that were not on ``before`` or are on an object that moved, most severe
    first (one per object)."""
    seen = hazards_seen(before, kb)
    now = hazards_seen(after, kb)
    moved = moved_objects(before, after)
    out: list[tuple[str, str]] = []
    for (obj, cls), _sev in sorted(now.items(), key=lambda kv: (-kv[1], kv[0])):
        if ((obj, cls) not in seen or obj in moved) and all(obj != o for o, _ in out):
            out.append((obj, cls))
    return out


def spec_as_it_stands(spec: SceneSpec, graph: SceneGraph) -> SceneSpec:
    """The perceived spec with the joint states of the scene graph just read: the planner picks
    which knob to turn or door to shut from joint states, and the scene file holds the start."""
    live = {o.name: o.joints for o in graph.objects}
    objects = [o.model_copy(update={"joint_states": live[o.name]}) if o.name in live else o for o in spec.objects]
    return spec.model_copy(update={"objects": objects})


def repair_fixes(found: list[tuple[str, str]], graph: SceneGraph, kb, *,
                 max_fixes: int) -> tuple[list[Fix], list[tuple[str, str]]]:
    """The new hazards (at most ``max_fixes``) with their roles bound from the graph just read
    (``plan.bind``); (class, problem) for those that cannot be bound."""
    from anomalygen.plan.bind import bind_fix

    fixes, problems = [], []
    for obj, cls in found[:max_fixes]:
        try:
            fixes.append(Fix(cls, obj, bind_fix(kb.hazard_classes[cls], obj, graph, kb)))
        except ItemFailed as exc:
            problems.append((cls, f"{cls} on {obj}: {exc}"))
    return fixes, problems


def repair_plan(task_id: str, found: list[tuple[str, str]], graph: SceneGraph, spec: SceneSpec, kb, *,
                max_fixes: int, sac_actions=()) -> tuple[Plan | None, list[tuple[str, str]]]:
    """One plan fixing the new hazards (at most ``max_fixes``); (class, problem) for those it cannot plan."""
    from anomalygen.plan.planner import merge_plans, plan_from_kb

    fixes, problems = repair_fixes(found, graph, kb, max_fixes=max_fixes)
    plans = []
    for f in fixes:
        try:
            plans.append(plan_from_kb(task_id, f.hazard_class, f.bindings, spec=spec, source="detected",
                                      sac_actions=sac_actions))
        except ItemFailed as exc:
            problems.append((f.hazard_class, f"{f.hazard_class} on {f.object}: {exc}"))
    if not plans:
        return None, problems
    merged = merge_plans(plans)  # run with this plan: its bindings resolve a single fix's variables
    steps = [st.model_copy(update={"id": f"recheck_{st.id}"}) for st in merged.subtasks]
    return merged.model_copy(update={"subtasks": steps}), problems
