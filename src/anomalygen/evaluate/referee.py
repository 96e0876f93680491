"""The referee: judges an execution against the builder's hidden ``truth.json``.

Why apart from the robot: the robot decides it is done when its own plan's final condition holds,
and that condition is built from what the robot perceived and chose. Whether the scene's real
hazard is gone is a different question, answered here from the truth manifest and the final scene
graph. The referee also counts the harm a fix can do: hazards present at the end that were not
there at the start (a glass knocked to the floor, a door left open), and interventions on
near-misses (moving a knife that was already shut in a drawer).
"""

from __future__ import annotations

import math

from anomalygen.scene.truth import class_matches
from anomalygen.schema import FixOutcome, HazardManifest, HazardOutcome, SceneGraph

MOVED_M = 0.05  # a near-miss object displaced further than this was acted on
TURNED = 0.1  # a near-miss joint (rad or m) moved further than this was acted on


def judge_fix(manifest: HazardManifest, initial: SceneGraph, final: SceneGraph, kb) -> FixOutcome:
    """The verdict on one execution: each manifest hazard resolved or not, and the harm done."""
    from anomalygen.knowledge.predicates import PredicateError, evaluate, match_class

    names = {o.name for o in final.objects}
    hazards: list[HazardOutcome] = []
    for h in manifest.hazards:
        hc = kb.hazard_classes.get(h.hazard_class)
        if hc is None or h.object not in names:
            hazards.append(HazardOutcome(hazard_class=h.hazard_class, object=h.object, resolved=False,
                                         detail="unknown class or object missing from the final scene"))
            continue
        try:
            results = [evaluate(call, final) for call in h.success]
            still = bool(match_class(hc, final, fixed={h.variable: h.object}))
        except PredicateError as exc:
            hazards.append(HazardOutcome(hazard_class=h.hazard_class, object=h.object, resolved=False,
                                         detail=f"cannot evaluate: {exc}"))
            continue
        failed = [r.explanation or r.call.name for r in results if not r.holds]
        if still:
            failed.append(f"{h.hazard_class} still holds for {h.object}")
        hazards.append(HazardOutcome(hazard_class=h.hazard_class, object=h.object, resolved=not failed,
                                     detail="; ".join(failed) if failed else "fixed"))
    before = {(c, o) for c, o, _ in class_matches(initial, kb)}
    after = {(c, o) for c, o, _ in class_matches(final, kb)}
    return FixOutcome(
        hazards=hazards,
        resolved=all(h.resolved for h in hazards),
        new_hazards=[f"{c} on {o}" for c, o in sorted(after - before)],
        interventions_on_safe=[n.object for n in manifest.near_misses if _acted_on(n.object, initial, final)],
    )


def _acted_on(name: str, initial: SceneGraph, final: SceneGraph) -> bool:
    a = next((o for o in initial.objects if o.name == name), None)
    b = next((o for o in final.objects if o.name == name), None)
    if a is None or b is None:
        return False
    if math.dist(a.position, b.position) > MOVED_M:
        return True
    before = {j.name: j.value for j in a.joints}
    return any(abs(j.value - before.get(j.name, j.value)) > TURNED for j in b.joints)
