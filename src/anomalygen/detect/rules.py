"""The rule detector: every knowledge-base hazard class's preconditions, evaluated on the scene graph.

Why rules at all: they need no LLM, are deterministic, and every hit comes with the predicate
explanations that made it fire, so a miss can be traced to a knowledge-base rule rather than to a
model's mood. They read only the scene graph (through the same predicates planning and evaluation
use), never the task.

Ranking. Each (object, class) pair is one candidate, scored by the class's severity: the knowledge
base uses severity to settle overlaps between classes. One exception: a class that lists its typical
hazard objects (only "reduce tripping hazards" does, because it fires on *any* plain object on the
floor) fires on other objects only weakly, so an apple or a cup that happens to lie on the floor
scores ATYPICAL_PENALTY lower and does not outrank, say, the litter next to it. Equal scores are
broken by typicality, by specificity (a class with more preconditions that all hold explains the
object more sharply), then by names, so the order is deterministic. When several objects are
hazardous, the top of the list should cover them all rather than repeat one object under three
classes: every object's best hypothesis comes before any object's second one (the planner makes one
fix per object, so a second class for the iron must not push the soda can beside it out of the top k).
"""

from __future__ import annotations

from dataclasses import dataclass

from anomalygen.schema import Hypothesis, SceneGraph

#: Score taken off when a class with a curated hazard-object list fires on an object not on it.
ATYPICAL_PENALTY = 0.2


@dataclass(frozen=True)
class Candidate:
    """One hazard class firing on one object, before ranking."""

    hazard_class: str
    object: str
    category: str
    severity: float
    score: float
    typical: bool  # on the class's curated hazard-object list
    specificity: int  # number of preconditions that hold
    problem: str
    solution: str
    explanation: str
    bindings: tuple[tuple[str, str], ...]


def _fill(template: str, slots: dict[str, str]) -> str:
    out = template
    for key, value in slots.items():
        out = out.replace("{" + key + "}", value)
    return out


def _hazard_instance(hc, bindings: dict[str, str]) -> str:
    """The object the class is about: its hazard variable, else $target, else the first binding."""
    for var in (hc.hazard_variable, "$hazard", "$target"):
        if var in bindings:
            return bindings[var]
    return next(iter(bindings.values()), "")


def candidates(graph: SceneGraph, kb=None) -> list[Candidate]:
    """Every (object, class) hit in the scene, de-duplicated (best match kept), unranked."""
    from anomalygen.knowledge.predicates import PredicateError, evaluate, match_class

    kb = kb if kb is not None else _kb()
    by_name = {o.name: o for o in graph.objects}
    best: dict[tuple[str, str], Candidate] = {}
    for hc_id in sorted(kb.hazard_classes):
        hc = kb.hazard_classes[hc_id]
        try:
            matches = match_class(hc, graph)
        except PredicateError:
            continue  # a malformed rule must not hide every other class; KB tests catch it
        for m in matches:
            obj = _hazard_instance(hc, m.bindings)
            if obj not in by_name:
                continue
            category = by_name[obj].category
            slots = {"hazard": obj, "target": m.bindings.get("$target", obj)}
            slots["container"] = m.bindings.get("$container") or (hc.default_containers[0].replace("_", " ") if hc.default_containers else "a safe place")
            slots["support"] = m.bindings.get("$support") or (hc.default_supports[0].replace("_", " ") if hc.default_supports else "a safe surface")
            solution = _fill(hc.solution, slots) if hc.solution else "; ".join(_fill(str(s), {}) for s in hc.recipe)
            curated = getattr(hc, "hazard_objects", None) or []
            typical = not curated or category in curated
            score = hc.severity - (0.0 if typical else ATYPICAL_PENALTY)
            cand = Candidate(
                hazard_class=hc.id,
                object=obj,
                category=category,
                severity=hc.severity,
                score=round(score, 6),
                typical=typical,
                specificity=len(hc.preconditions),
                problem=f"{hc.name}: {obj} ({category.replace('_', ' ')}) — {hc.why}",
                solution=solution,
                explanation=f"{hc.id} holds because {_because(hc, graph, m.bindings, evaluate)}"
                + ("" if typical else f" (but a {category} is not a typical object of this class)"),
                bindings=tuple(sorted(m.bindings.items())),
            )
            key = (obj, hc.id)
            if key not in best or (cand.score, cand.bindings) > (best[key].score, best[key].bindings):
                best[key] = cand
    return list(best.values())


def _because(hc, graph: SceneGraph, bindings: dict[str, str], evaluate) -> str:
    """The preconditions' own descriptions of the scene state, de-duplicated, in class order.

    Each predicate describes what it saw ("knife_0 is 0.90 m above the floor", "knife_0 is not
    inside anything"), which reads correctly whether or not the call was negated.
    """
    parts: list[str] = []
    for call in hc.preconditions:
        text = evaluate(call, graph, bindings).explanation
        if text and text not in parts:
            parts.append(text)
    return "; ".join(parts)


def rank(cands: list[Candidate], k: int) -> list[Candidate]:
    """The top ``k`` by score, each object's n-th hypothesis after every object's (n-1)-th (distinct
    objects first, then second classes, ...); deterministic ties."""
    pool = sorted(cands, key=lambda c: (-c.score, not c.typical, -c.specificity, c.object, c.hazard_class))
    listed: dict[str, int] = {}
    tier = []
    for i, c in enumerate(pool):
        tier.append((listed.get(c.object, 0), i))
        listed[c.object] = listed.get(c.object, 0) + 1
    return [pool[i] for _, i in sorted(tier)[:k]]


def to_hypotheses(ranked: list[Candidate]) -> list[Hypothesis]:
    return [
        Hypothesis(
            rank=i,
            problem=c.problem,
            solution=c.solution,
            target_object=c.object,
            hazard_class=c.hazard_class,
            score=c.score,
            explanation=c.explanation,
        )
        for i, c in enumerate(ranked, start=1)
    ]


class RuleDetector:
    name = "rules"

    def __init__(self, kb=None):
        self.kb = kb

    def detect(self, graph: SceneGraph, k: int) -> list[Hypothesis]:
        return to_hypotheses(rank(candidates(graph, self.kb), k))


def _kb():
    from anomalygen.knowledge import load_kb

    return load_kb()
