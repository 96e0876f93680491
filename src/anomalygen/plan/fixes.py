"""Which detected hazards the robot fixes, and with which roles: the plan stage's choice, in one place.

Why its own module: the plan stage (``plan/stage.py``) turns the choice into one merged plan per scene;
the skill-level env's ``Pipeline`` agent (``anomalygen.agents``) turns the same choice into one ``fix``
call per hazard. Both must choose alike, hazard for hazard, or the agent would not be our pipeline.
"""

from __future__ import annotations

from dataclasses import dataclass

from anomalygen.errors import ItemFailed
from anomalygen.schema import DroppedFix, SceneGraph


@dataclass(frozen=True)
class Fix:
    """One hazard to fix: its class, the object at fault, and every role of the recipe bound."""

    hazard_class: str
    object: str
    bindings: dict[str, str]


def fixes_to_make(hypotheses: list[dict], kb, *, max_fixes: int, min_score: float) -> list[dict]:
    """Hypotheses worth acting on: a known class, a score at or above ``min_score``, one per object,
    most severe class first (ties by detector rank), at most ``max_fixes``."""
    seen: set[str] = set()
    out = []
    usable = [h for h in hypotheses if h.get("hazard_class") in kb.hazard_classes
              and float(h.get("score") or 0.0) >= min_score]
    for h in sorted(usable, key=lambda h: (-kb.hazard_classes[h["hazard_class"]].severity, h["rank"])):
        if h["target_object"] in seen:
            continue
        seen.add(h["target_object"])
        out.append(h)
    return out[:max_fixes]


def other_classes_of(hypotheses: list[dict], kb, chosen: dict, *, min_score: float) -> list[dict]:
    """The other usable hypotheses about ``chosen``'s object, most severe class first."""
    same = [h for h in hypotheses if h is not chosen and h.get("target_object") == chosen["target_object"]
            and h.get("hazard_class") in kb.hazard_classes and h.get("hazard_class") != chosen.get("hazard_class")
            and float(h.get("score") or 0.0) >= min_score]
    return sorted(same, key=lambda h: (-kb.hazard_classes[h["hazard_class"]].severity, h["rank"]))


def choose_fixes(hypotheses: list[dict], graph: SceneGraph, kb, *, max_fixes: int,
                 min_score: float) -> tuple[list[Fix], list[DroppedFix]]:
    """The fixes to make for a detection (hypotheses as JSON dicts), most severe first, each with its
    roles bound from the perceived graph (``plan.bind``), and the detected hazards left out with the
    binder's reason. Nothing worth acting on: no fixes. ItemFailed when there was something to fix and
    no fix could be bound."""
    from anomalygen.plan.bind import bind_fix

    fixes, dropped = [], []
    for first in fixes_to_make(hypotheses, kb, max_fixes=max_fixes, min_score=min_score):
        # the object's most severe class first; when its fix cannot be bound here (no container the
        # toy fits), the object's next detected class (the toy taken off the stairs)
        for hyp in [first, *other_classes_of(hypotheses, kb, first, min_score=min_score)]:
            hc = kb.hazard_classes[hyp["hazard_class"]]
            try:
                bindings = bind_fix(hc, hyp["target_object"], graph, kb)
            except ItemFailed as exc:
                dropped.append(DroppedFix(hazard_class=hc.id, object=hyp["target_object"], reason=str(exc)))
                continue
            fixes.append(Fix(hc.id, hyp["target_object"], bindings))
            break
    if dropped and not fixes:
        raise ItemFailed("; ".join(f"{d.hazard_class} on {d.object}: {d.reason}" for d in dropped))
    return fixes, dropped
