"""The builder's answer key: ``truth.json``, every hazard in a built scene, bound to instances.

Why a separate file: the robot side (detect, plan, learn) must work from what it perceives alone,
and success must be judged against what the builder really set up, not against the plan's own
final condition. The builder knows the intended hazard (its role bindings); it also checks the
settled scene for incidental hazards its placement created (a clutter item that ended in a
walkway), and lists hazard-class objects it left in a safe state as near-misses. Only the referee
(``anomalygen.evaluate.referee``) and the detection scorer read this file.

Success of a hazard is the class's own success predicates with the object at fault bound, and with
``*`` wherever the fix may choose (any container, any support): a robot that puts the knife into
another closed drawer than the builder had in mind has still fixed it. Predicates about an object
the robot chooses (``joint_closed(object=$container)``) are left out; the referee additionally
requires that the class's preconditions no longer hold for the object at fault.
"""

from __future__ import annotations

from anomalygen.schema import (
    HazardManifest,
    ManifestHazard,
    NearMiss,
    PredicateCall,
    SceneGraph,
    SceneSpec,
)

TRUTH_FILE = "truth.json"
CHOSEN_BY_THE_FIX = ("container", "support")  # predicate arguments the fix may fill with any object


def load_manifest(scene_dir) -> HazardManifest | None:
    """The scene's truth.json (for the referee and the scorers only), or None when there is none."""
    from pathlib import Path

    from anomalygen.runfolder import try_read_model

    return try_read_model(Path(scene_dir) / TRUTH_FILE, HazardManifest)


def bound_success(hc, fault_variable: str, fault_object: str, bindings: dict[str, str]) -> list[PredicateCall]:
    """The class's success predicates over the object at fault, with '*' where the fix chooses."""
    fixed = {fault_variable: fault_object}
    if bindings.get("$target") == fault_object or fault_variable == "$target":
        fixed.setdefault("$target", bindings.get("$target", fault_object))
    out: list[PredicateCall] = []
    for call in hc.success:
        args = {}
        keep = True
        for key, value in call.args.items():
            if isinstance(value, str) and value.startswith("$"):
                if value in fixed:
                    args[key] = fixed[value]
                elif key in CHOSEN_BY_THE_FIX:
                    args[key] = "*"
                else:
                    keep = False  # about an object the fix picks (e.g. the container's door)
                    break
            else:
                args[key] = value
        if keep:
            out.append(PredicateCall(name=call.name, args=args, negate=call.negate))
    return out


def class_matches(graph: SceneGraph, kb) -> list[tuple[str, str, dict[str, str]]]:
    """Every (class id, object at fault, bindings) the knowledge base finds on ``graph``.

    Only objects typical of the class count (a class with a curated object list fires on those),
    the same plausibility test the knowledge base applies everywhere else.
    """
    from anomalygen.knowledge.predicates import PredicateError, match_class

    by_name = {o.name: o for o in graph.objects}
    found: dict[tuple[str, str], dict[str, str]] = {}
    for hc_id in sorted(kb.hazard_classes):
        hc = kb.hazard_classes[hc_id]
        try:
            matches = match_class(hc, graph)
        except PredicateError:
            continue
        for m in matches:
            obj = m.bindings.get(hc.hazard_variable) or m.bindings.get("$hazard") or m.bindings.get("$target")
            if obj not in by_name:
                continue
            if hc.hazard_objects and by_name[obj].category not in hc.hazard_objects:
                continue
            found.setdefault((hc_id, obj), dict(m.bindings))
    return [(hc_id, obj, b) for (hc_id, obj), b in sorted(found.items())]


def hazard_manifest(spec: SceneSpec, hazard_class: str | None, graph: SceneGraph, kb) -> HazardManifest:
    """The manifest of a settled, validated scene built for a task of ``hazard_class`` (None: the
    builder set up no hazard, and only what the settled scene shows is listed)."""
    category = {o.name: o.category for o in graph.objects}
    hazards: list[ManifestHazard] = []
    hc = kb.hazard_classes.get(hazard_class) if hazard_class else None
    intended: set[str] = set()
    if hc is not None:
        var = hc.hazard_variable if hc.hazard_variable in spec.bindings else "$hazard"
        obj = spec.bindings.get(var) or spec.bindings.get("$target")
        if obj:
            intended.add(obj)
            hazards.append(_hazard(hc, var, obj, category.get(obj, ""), spec.bindings))
    for hc_id, obj, bindings in class_matches(graph, kb):
        if obj in intended or any(h.object == obj for h in hazards):
            continue  # one entry per object at fault: the builder's intended class wins
        other = kb.hazard_classes[hc_id]
        var = other.hazard_variable if other.hazard_variable in bindings else "$hazard"
        hazards.append(_hazard(other, var, obj, category.get(obj, ""), bindings))
    return HazardManifest(
        scene_id=spec.scene_id,
        task_id=spec.task_id,
        hazards=hazards,
        near_misses=near_misses(graph, kb, {h.object for h in hazards}),
    )


def near_misses(graph: SceneGraph, kb, hazardous: set[str]) -> list[NearMiss]:
    """Objects that could be the hazard of some class by what they are, yet no class fires on them."""
    out: list[NearMiss] = []
    for o in graph.objects:
        if o.name in hazardous:
            continue
        for hc_id in sorted(kb.hazard_classes, key=lambda c: -kb.hazard_classes[c].severity):
            hc = kb.hazard_classes[hc_id]
            if hc.hazard_variable != "$hazard" or o.category not in kb.hazard_candidates(hc):
                continue
            out.append(NearMiss(object=o.name, category=o.category, looks_like=hc_id,
                                why_safe=f"a {o.category} that no precondition set of {hc_id} holds for"))
            break
    return out


def _hazard(hc, var: str, obj: str, category: str, bindings: dict[str, str]) -> ManifestHazard:
    return ManifestHazard(
        hazard_class=hc.id,
        object=obj,
        category=category,
        severity=hc.severity,
        variable=var,
        bindings=dict(bindings),
        success=bound_success(hc, var, obj, bindings),
    )
