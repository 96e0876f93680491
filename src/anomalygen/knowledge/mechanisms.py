"""Hazard classes composed from mechanisms: new combinations are data, not code.

A household hazard is a *mechanism* (fire by a heat source, electricity by water, a child reaching
something, a fall from an edge, ...) applied to a *kind* of object (what it is: sharp, combustible,
an appliance), optionally in a dangerous *condition* (on, open, handle out) and at a *place* (low,
at an edge, on the stairs, next to a lit burner), fixed by a *fix* (recipe and success). Each of
these fragments is a list of knowledge-base predicate calls in ``data/knowledge/mechanisms.json``;
``compose`` concatenates them into an ordinary :class:`HazardClass`, so detection, planning, the
builder and the referee use a composed class exactly like a hand-written one.

The 26 hand-written classes (``hazard_classes.json``) stay the loaded definitions of their ids; the
mechanism data names, for each, the composition it equals (``legacy``), which the tests check.
"""

from __future__ import annotations

import functools
import json
from typing import Literal

from pydantic import Field

from anomalygen.knowledge.models import (
    KNOWLEDGE_DIR,
    ArticulationTemplate,
    Composed,
    HazardClass,
    KBModel,
    RecipeStep,
)
from anomalygen.schema import HazardCategory, Placement, PredicateCall

FAULT = "$F"  # the placeholder the fragments use for the mechanism's object at fault
#: Cosmetic: how composed class names join a kind's words to a place's.
NAME_JOIN = " "


class PartState(KBModel):
    """The articulated part a fragment sets up (the variable defaults to the object at fault)."""

    variable: str = FAULT
    part: str
    initial_state: Literal["open", "closed", "on", "off", "other"]
    target_state: Literal["open", "closed", "on", "off", "other"]


class Relation(KBModel):
    """How a place relates the object at fault to another named object, for reading a user's line:
    ``on``/``inside``/``near`` another object that fills ``variable`` or is of ``category``."""

    type: str = Field(description="on, inside or near; alternatives 'on|inside' (a blanket 'in' the crib lies on it)")
    variable: str | None = None
    category: str | None = None


class Fragment(KBModel):
    """A reusable piece of a class: calls over ``$F`` (and any variables it introduces)."""

    words: str = ""
    calls: list[PredicateCall] = Field(default_factory=list)
    cues: list[str] = Field(default_factory=list, description="words that say this fragment in a user's line")
    variables: dict[str, str] = Field(default_factory=dict, description="variables it introduces, with what they are")
    params: dict[str, str] = Field(default_factory=dict, description="values a fix may use, e.g. {label}")
    placements: list[Placement] = Field(default_factory=list, description="scenario placements that set it up; '{other}' = the related object")
    hazard_objects: list[str] = Field(default_factory=list, description="a kind's curated objects (empty: any that fits)")
    not_drawn: list[str] = Field(default_factory=list, description="of those, objects the generator does not draw "
                                 "yet (a user's line, the truth and the detector still hold them)")
    articulation: PartState | None = None
    states: dict[str, list[str]] = Field(default_factory=dict, description="instance states a scene must show, by variable")
    relation: Relation | None = None


class Fix(KBModel):
    words: str
    success_words: str
    recipe: list[RecipeStep]
    success: list[PredicateCall]
    variables: dict[str, str] = Field(default_factory=dict)


class Composition(KBModel):
    """One row of a mechanism: ``kind`` may list alternatives 'a|b' (one class each)."""

    kind: str
    place: str
    fix: str
    condition: str | None = None
    legacy: str | None = Field(None, description="the hand-written class this composition equals")
    id: str | None = Field(None, description="class id (default: '<kind>_<place>'); ignored for legacy rows")
    name: str | None = Field(None, description="the class's name (default: the fragments' words)")
    fault: str | None = None
    severity: float | None = None
    why: str | None = Field(None, description="why this combination is dangerous, where the mechanism's "
                            "own text speaks of other objects (default: the mechanism's)")
    why_by: dict[str, str] = Field(default_factory=dict, description="a reason per category or property where "
                                   "``why`` does not fit every object the row draws (HazardClass.why_by)")
    people: list[str] = Field(default_factory=list, description="the people at risk, where the mechanism's "
                              "own list names some this combination does not endanger (default: the mechanism's)")
    containers: list[str] = Field(default_factory=list)
    supports: list[str] = Field(default_factory=list)
    targets: list[str] = Field(default_factory=list)
    rooms: list[str] = Field(default_factory=list)
    placements: list[Placement] = Field(default_factory=list, description="overrides the place's placements")
    assume_condition: bool = Field(False, description="a user's line need not state the condition (a heater is on)")
    undrawn_because: str | None = Field(None, description="why brainstorming does not draw this class yet (None: "
                                        "it does); a user's line, the truth and the detector still hold it")


class Mechanism(KBModel):
    id: str
    name: str
    category: HazardCategory
    danger: str
    why: str
    at_risk: str
    people: list[str] = Field(default_factory=list)
    severity: float = Field(ge=0, le=1)
    fault: str = "$hazard"
    compositions: list[Composition]


class Unsupported(KBModel):
    """Words that say a hazard no mechanism can build, and why (a line with them is refused)."""

    cues: list[str]
    reason: str


class MechanismSet(KBModel):
    kinds: dict[str, Fragment]
    conditions: dict[str, Fragment]
    places: dict[str, Fragment]
    fixes: dict[str, Fix]
    mechanisms: list[Mechanism]
    unsupported: list[Unsupported] = Field(default_factory=list)

    def mechanism(self, mechanism_id: str) -> Mechanism:
        return next(m for m in self.mechanisms if m.id == mechanism_id)


@functools.cache
def load_mechanisms() -> MechanismSet:
    raw = json.loads((KNOWLEDGE_DIR / "mechanisms.json").read_text(encoding="utf-8"))
    return MechanismSet.model_validate({k: v for k, v in raw.items() if not k.startswith("_")})


# --------------------------------------------------------------------------- substitution


def _sub(value, fault: str, params: dict[str, str]):
    if not isinstance(value, str):
        return value
    if value == FAULT:
        return fault
    for key, text in params.items():
        value = value.replace("{" + key + "}", text)
    return value


def _calls(calls: list[PredicateCall], fault: str, params: dict[str, str]) -> list[PredicateCall]:
    return [c.model_copy(update={"args": {k: _sub(v, fault, params) for k, v in c.args.items()}}) for c in calls]


def _steps(steps: list[RecipeStep], fault: str, params: dict[str, str]) -> list[RecipeStep]:
    return [s.model_copy(update={"args": {k: _sub(v, fault, params) for k, v in s.args.items()}}) for s in steps]


def _words(text: str) -> str:
    return text.replace("_", " ")


# --------------------------------------------------------------------------- composition


def rows(ms: MechanismSet) -> list[tuple[Mechanism, Composition, str]]:
    """Every (mechanism, composition row, single kind) the data describes, in data order."""
    return [(m, c, k) for m in ms.mechanisms for c in m.compositions for k in c.kind.split("|")]


def class_id(m: Mechanism, c: Composition, kind: str) -> str:
    if c.legacy:
        return c.legacy
    if c.id and "|" not in c.kind:
        return c.id
    return (c.id or "{kind}_{place}").format(kind=kind, place=c.place, mechanism=m.id)


def compose(ms: MechanismSet, m: Mechanism, c: Composition, kind_id: str) -> HazardClass:
    """The HazardClass of one composition: kind + condition + place calls, the fix's recipe and success."""
    kind, place, fix = ms.kinds[kind_id], ms.places[c.place], ms.fixes[c.fix]
    cond = ms.conditions[c.condition] if c.condition else None
    fault = c.fault or m.fault
    parts = [kind, *([cond] if cond else []), place]
    params: dict[str, str] = {}
    for p in parts:
        params.update(p.params)
    pre = [call for p in parts for call in _calls(p.calls, fault, params)]
    variables = {fault: f"the {_words(kind.words)} at fault"}
    for p in parts:
        variables.update({k: v for k, v in p.variables.items() if k != fault})
    variables.update(fix.variables)
    recipe = _steps(fix.recipe, fault, params)
    for step in recipe:
        for v in step.args.values():
            if isinstance(v, str) and v.startswith("$"):
                variables.setdefault(v, v.lstrip("$"))
    art = next((p.articulation for p in parts if p.articulation is not None), None)
    articulation = None
    if art is not None:
        articulation = ArticulationTemplate(
            variable=fault if art.variable == FAULT else art.variable, part=_sub(art.part, fault, params),
            initial_state=art.initial_state, target_state=art.target_state, function=f"{_words(kind.words)} control",
        )
    placements = c.placements or list(dict.fromkeys(place.placements))
    name = c.name or NAME_JOIN.join(w for w in (_words(kind.words).capitalize(), cond.words if cond else "", place.words) if w)
    slots = {"hazard": "{hazard}", "container": "{container}", "support": "{support}"}
    return HazardClass(
        id=class_id(m, c, kind_id),
        name=name,
        category=m.category,
        paper_class=False,
        at_risk=m.at_risk,
        people=list(c.people or m.people),
        why=c.why or m.why,
        why_by=dict(c.why_by),
        severity=c.severity if c.severity is not None else m.severity,
        variables=variables,
        hazard_variable=fault,
        preconditions=pre,
        recipe=recipe,
        success=_calls(fix.success, fault, params),
        placements=placements,
        default_containers=list(c.containers),
        default_supports=list(c.supports),
        hazard_objects=list(kind.hazard_objects),
        not_drawn=list(kind.not_drawn),
        undrawn_because=c.undrawn_because,
        target_assets=list(c.targets),
        rooms=list(c.rooms),
        articulation=articulation,
        mechanism=m.danger,
        solution=fix.words.format(**slots),
        success_text=fix.success_words.format(**slots),
        composition=Composed(mechanism=m.id, kind=kind_id, place=c.place, fix=c.fix, condition=c.condition,
                             legacy=bool(c.legacy)),
    )


def composed_classes(ms: MechanismSet | None = None) -> list[HazardClass]:
    """Every class the mechanism data composes, legacy rows included (their ids are the hand-written ones)."""
    ms = ms or load_mechanisms()
    return [compose(ms, m, c, k) for m, c, k in rows(ms)]


def setup_states(ms: MechanismSet, hc: HazardClass) -> dict[str, list[str]]:
    """Instance states, by variable, a scene of ``hc`` must show (a sink holding water)."""
    comp = hc.composition
    if comp is None:
        return {}
    fault = hc.hazard_variable
    out: dict[str, list[str]] = {}
    frags = [ms.kinds.get(comp.kind), ms.conditions.get(comp.condition or ""), ms.places.get(comp.place)]
    for frag in frags:
        for var, states in (frag.states if frag else {}).items():
            out.setdefault(fault if var == FAULT else var, []).extend(states)
    return out


def same_calls(a: list[PredicateCall], b: list[PredicateCall]) -> bool:
    """The same calls, in any order (the order of preconditions does not change what matches)."""
    key = lambda c: (c.name, c.negate, sorted((k, str(v)) for k, v in c.args.items()))  # noqa: E731
    return sorted(map(key, a)) == sorted(map(key, b))


def mechanism_problems(ms: MechanismSet, objects: set[str]) -> list[str]:
    """Broken references in the mechanism data (unknown fragment, duplicate id)."""
    out: list[str] = []
    seen: set[str] = set()
    for m, c, k in rows(ms):
        where = f"mechanism {m.id}"
        for label, table, key in (("kind", ms.kinds, k), ("place", ms.places, c.place), ("fix", ms.fixes, c.fix)):
            if key not in table:
                out.append(f"{where}: unknown {label} {key!r}")
        if c.condition and c.condition not in ms.conditions:
            out.append(f"{where}: unknown condition {c.condition!r}")
        cid = class_id(m, c, k)
        if cid in seen:
            out.append(f"{where}: class id {cid!r} composed twice")
        seen.add(cid)
    for kid, frag in ms.kinds.items():
        out += [f"kind {kid}: unknown object {o}" for o in frag.hazard_objects if o not in objects]
    return out
