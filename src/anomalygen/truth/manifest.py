"""The builder's answer key: ``truth.json``, every hazard in a built scene, bound to instances.

Why a separate file: the robot side (detect, plan, learn) must work from what it perceives alone,
and success must be judged against what the builder really set up, not against the plan's own
final condition. The intended hazard comes from what the builder set out to build (the task's class
and the builder's role bindings, and the judgement mix's deliberate extras: a second hazard, a
near-miss placed just inside a threshold), confirmed on the settled scene (build validation fails a
scene whose settled state does not show the task's hazard). Incidental hazards — what the knowledge
base's matcher finds on the settled scene besides (a clutter item that ended in a walkway) — are
listed too, and every entry says which it is (``source``). Hazard-class objects left safe are the
near-misses, with their kind (well clear, borderline just outside a threshold, or a part left in a
safe state). Only the referee package reads this file; the builder writes it through
:func:`hazard_manifest`.

Success of a hazard is the class's own success predicates with the object at fault bound, and with
``*`` wherever the fix may choose (any container, any support): a robot that puts the knife into
another closed drawer than the builder had in mind has still fixed it. Predicates about an object
the robot chooses (``joint_closed(object=$container)``) are left out; the referee additionally
requires that the class's preconditions no longer hold for the object at fault.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from anomalygen.scene_files import TRUTH
from anomalygen.schema import (
    HazardManifest,
    ManifestHazard,
    NearMiss,
    PredicateCall,
    SceneGraph,
    SceneSpec,
)

CHOSEN_BY_THE_FIX = ("container", "support")  # predicate arguments the fix may fill with any object


def load_manifest(scene_dir) -> HazardManifest | None:
    """The scene's truth.json, or None when there is none."""
    from pathlib import Path

    from anomalygen.runfolder import try_read_model

    return try_read_model(Path(scene_dir) / TRUTH, HazardManifest)


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


@dataclass(frozen=True)
class Intent:
    """What the builder meant one extra object to be: ``hazard`` of ``hazard_class`` (a second hazard, a
    near-miss placed just inside a threshold), or a near-miss of kind ``borderline`` or ``state``."""

    kind: Literal["hazard", "borderline", "state"]
    hazard_class: str
    why: str = ""


def intended_hazard(spec: SceneSpec, hazard_class: str | None, graph: SceneGraph, kb) -> tuple[str, str] | None:
    """(object, class variable) of the task's hazard as the builder bound it, or None (no hazard set up).

    Raises ValueError when the settled scene does not show it: the builder validates the class's
    preconditions on the settled state first, so this never fires for a scene that passed validation.
    """
    from anomalygen.knowledge.predicates import PredicateError, match_class

    hc = kb.hazard_classes.get(hazard_class) if hazard_class else None
    if hc is None:
        return None
    var = hc.hazard_variable if hc.hazard_variable in spec.bindings else "$hazard"
    obj = spec.bindings.get(var) or spec.bindings.get("$target")
    if not obj:
        return None
    fixed = {v: spec.bindings[v] for v in hc.variable_names() if v in spec.bindings}
    try:
        shown = bool(match_class(hc, graph, fixed=fixed))
    except PredicateError:
        shown = False
    if not shown:
        raise ValueError(f"the settled scene does not show the intended {hc.id} on {obj}")
    return obj, var


def hazard_manifest(spec: SceneSpec, hazard_class: str | None, graph: SceneGraph, kb,
                    intents: dict[str, Intent] | None = None) -> HazardManifest:
    """The manifest of a settled, validated scene built for a task of ``hazard_class`` (None: the
    builder set up no hazard, and only what the settled scene shows is listed). ``intents``: what the
    judgement mix meant its extra objects to be (a hazard it meant counts as intended once the
    settled scene shows it; one that did not come about is a borderline near-miss)."""
    intents = intents or {}
    category = {o.name: o.category for o in graph.objects}
    hazards: list[ManifestHazard] = []
    task = intended_hazard(spec, hazard_class, graph, kb)
    if task is not None:
        obj, var = task
        hazards.append(_hazard(kb.hazard_classes[hazard_class], var, obj, category.get(obj, ""), spec.bindings,
                               "intended"))
    for hc_id, obj, bindings in class_matches(graph, kb):
        same = next((h for h in hazards if h.object == obj), None)
        if same is not None:  # one entry per object at fault: the builder's intended class wins
            if hc_id != same.hazard_class:
                same.also_fires.append(hc_id)
            continue
        other = kb.hazard_classes[hc_id]
        var = other.hazard_variable if other.hazard_variable in bindings else "$hazard"
        meant = intents.get(obj)
        source = "intended" if meant is not None and meant.kind == "hazard" and meant.hazard_class == hc_id else "incidental"
        hazards.append(_hazard(other, var, obj, category.get(obj, ""), bindings, source))
    return HazardManifest(
        scene_id=spec.scene_id,
        task_id=spec.task_id,
        hazards=hazards,
        near_misses=near_misses(graph, kb, {h.object for h in hazards}, intents),
    )


def near_misses(graph: SceneGraph, kb, hazardous: set[str], intents: dict[str, Intent] | None = None) -> list[NearMiss]:
    """Objects that could be the hazard of some class by what they are, yet no class fires on them.

    The kind says why it is a near-miss: ``borderline`` (the mix placed it just outside a threshold,
    or just inside and it settled outside), ``state`` (it resembles a class about a part's state: a
    knob at off, a door ajar a few degrees), else ``object``.
    """
    intents = intents or {}
    out: list[NearMiss] = []
    for o in graph.objects:
        if o.name in hazardous:
            continue
        meant = intents.get(o.name)
        looks = _looks_like(o, kb) or (meant.hazard_class if meant is not None else None)
        if looks is None:
            continue
        kind = "state" if _about_state(kb.hazard_classes[looks]) else "object"
        why = f"a {o.category} that no precondition set of {looks} holds for"
        if meant is not None:
            kind = "borderline" if meant.kind in ("hazard", "borderline") else meant.kind
            why = meant.why or why
        out.append(NearMiss(object=o.name, category=o.category, looks_like=looks, why_safe=why, kind=kind))
    return out


def _looks_like(o, kb) -> str | None:
    """The most severe class whose object at fault this object could be by what it is."""
    for hc_id in sorted(kb.hazard_classes, key=lambda c: (-kb.hazard_classes[c].severity, c)):
        hc = kb.hazard_classes[hc_id]
        if hc.hazard_variable == "$hazard" and o.category in kb.hazard_candidates(hc):
            return hc_id
        if hc.about_target and o.category in _target_categories(hc):
            return hc_id
    return None


def _target_categories(hc) -> set[str]:
    """Categories a ``$target`` class names in its category_is precondition (a fridge, a toilet)."""
    out: set[str] = set()
    for call in hc.preconditions:
        if call.name == "category_is" and call.args.get("object") == "$target" and not call.negate:
            out |= {c.strip() for c in str(call.args.get("category", "")).split("|")}
    return out


def _about_state(hc) -> bool:
    return any(c.name in ("joint_open", "joint_closed") and not c.negate for c in hc.preconditions)


def _hazard(hc, var: str, obj: str, category: str, bindings: dict[str, str], source: str) -> ManifestHazard:
    return ManifestHazard(
        hazard_class=hc.id,
        source=source,
        object=obj,
        category=category,
        severity=hc.severity,
        variable=var,
        bindings=dict(bindings),
        success=bound_success(hc, var, obj, bindings),
    )
