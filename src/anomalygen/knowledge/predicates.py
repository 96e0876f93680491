"""Predicates over a :class:`~anomalygen.schema.SceneGraph`: the one vocabulary for hazards and fixes.

Detection (is this scene hazardous?), planning (what must hold after each step?) and evaluation (did
the robot make the scene safe?) all evaluate the same predicates on the same observation, so a hazard
class means one thing everywhere. Predicates read only the scene graph (never the task), which is
what keeps the rule detector honest.

Argument values that start with ``$`` are role variables resolved through ``bindings``; ``"*"``
means "any object"; several alternatives are written ``"a|b"``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable

from pydantic import BaseModel, ConfigDict

from anomalygen.knowledge.models import PredicateSpec
from anomalygen.schema import (
    CLOSED_TOL,
    GraphObject,
    PredicateCall,
    PredicateResult,
    SceneGraph,
    part_labels,
    shut_by,
)

#: Horizontal clearance (m) from furniture/appliances beyond which a floor object is "in the walkway".
WALKWAY_CLEARANCE = 0.3
#: Properties of the objects that line a room (a floor object close to one of them is out of the way).
ROOM_FIXTURES = ("furniture", "appliance")
#: Open fraction of a control from which it counts as on (``switch_off_appliance`` uses the same 0.5).
ON_FRACTION = 0.5
#: Instance states that say a control-less thing is on (a lit candle).
ON_STATES = ("on", "lit")
#: The values a yes/no predicate argument (``near``'s ``walls_separate``) may take.
FLAG_VALUES = ("true", "false")


def parse_flag(raw: object) -> bool | None:
    """A yes/no argument's value: True for 'true', False for 'false' (any case, spaces ignored), None
    for anything else. One reading for the predicate and for the knowledge base's class check."""
    value = str(raw).strip().lower()
    return value == "true" if value in FLAG_VALUES else None


class PredicateError(ValueError):
    """A call that cannot be evaluated: unknown predicate, missing argument, unbound variable."""


class Match(BaseModel):
    """One way a hazard class holds in a scene: variable bindings, why, and a ranking score."""

    model_config = ConfigDict(frozen=True)

    bindings: dict[str, str]
    explanation: str
    score: float


# --------------------------------------------------------------------------- helpers


class _Ctx:
    def __init__(self, graph: SceneGraph, bindings: dict[str, str]):
        self.graph = graph
        self.bindings = bindings
        self._by_name = {o.name: o for o in graph.objects}

    def name(self, call: PredicateCall, arg: str) -> str:
        if arg not in call.args:
            raise PredicateError(f"{call.name}: missing argument '{arg}'")
        value = str(call.args[arg])
        if value.startswith("$"):
            if value not in self.bindings:
                raise PredicateError(f"{call.name}: variable {value} is not bound")
            return self.bindings[value]
        return value

    def obj(self, call: PredicateCall, arg: str = "object") -> GraphObject:
        name = self.name(call, arg)
        try:
            return self._by_name[name]
        except KeyError:
            raise PredicateError(f"{call.name}: no object '{name}' in scene {self.graph.scene_id}") from None

    def num(self, call: PredicateCall, arg: str, default: float | None = None) -> float | None:
        if arg not in call.args:
            return default
        try:
            return float(call.args[arg])
        except (TypeError, ValueError):
            raise PredicateError(f"{call.name}: argument '{arg}' must be a number, got {call.args[arg]!r}") from None

    def flag(self, call: PredicateCall, arg: str) -> bool:
        """An optional yes/no argument: absent or 'false' is False, 'true' is True, anything else an error."""
        value = parse_flag(call.args.get(arg, "false"))
        if value is None:
            raise PredicateError(f"{call.name}: argument '{arg}' must be 'true' or 'false', got {call.args[arg]!r}")
        return value

    def relations(self, subject: str, predicate: str) -> list[str | None]:
        return [r.object for r in self.graph.relations if r.subject == subject and r.predicate == predicate]


def _alternatives(value: object) -> list[str]:
    return [v.strip() for v in str(value).split("|") if v.strip()]


def _base(instance: str | None) -> str | None:
    """``counter_0:top`` -> ``counter_0`` (relations may name a surface of an object)."""
    return None if instance is None else instance.split(":", 1)[0]


def aabb_gap(a: GraphObject, b: GraphObject, *, horizontal: bool = False) -> float:
    """Distance between two axis-aligned boxes (0 when they touch or overlap)."""
    axes = (0, 1) if horizontal else (0, 1, 2)
    gaps = [max(0.0, abs(a.position[i] - b.position[i]) - (a.size[i] + b.size[i]) / 2) for i in axes]
    return math.sqrt(sum(g * g for g in gaps))


def _label_matches(label: str, wanted: list[str]) -> bool:
    return "*" in wanted or label in wanted


# --------------------------------------------------------------------------- predicates

Impl = Callable[[_Ctx, PredicateCall], tuple[bool, str]]
PREDICATES: dict[str, PredicateSpec] = {}
_IMPLS: dict[str, Impl] = {}


def _predicate(name: str, args: dict[str, str], meaning: str):
    def deco(fn: Impl) -> Impl:
        PREDICATES[name] = PredicateSpec(name=name, args=args, meaning=meaning)
        _IMPLS[name] = fn
        return fn

    return deco


@_predicate(
    "has_property",
    {"object": "variable or instance", "property": "a property, or alternatives 'a|b' (any of them)"},
    "The object's perceived properties include the property (any of the alternatives).",
)
def _has_property(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    obj = ctx.obj(call)
    return _any_of(obj.name, _alternatives(call.args.get("property", "")), obj.properties)


def _any_of(name: str, wanted: list[str], present) -> tuple[bool, str]:
    """Holds when any alternative is among the object's words (its properties, its states)."""
    found = [w for w in wanted if w in present]
    return bool(found), f"{name} is {'/'.join(found) or 'not ' + '/'.join(wanted)}"


@_predicate(
    "category_is",
    {"object": "variable or instance", "category": "catalogue name, or alternatives 'A|B'"},
    "The object's catalogue category is one of the given names.",
)
def _category_is(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    obj = ctx.obj(call)
    wanted = _alternatives(call.args.get("category", ""))
    return obj.category in wanted, f"{obj.name} is a {obj.category}"


@_predicate("on_floor", {"object": "variable or instance"}, "The object rests directly on the floor.")
def _on_floor(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    obj = ctx.obj(call)
    return obj.on_floor, f"{obj.name} is {'on' if obj.on_floor else 'off'} the floor"


@_predicate(
    "height_above_floor",
    {"object": "variable or instance", "max": "metres (optional)", "min": "metres (optional)"},
    "The bottom of the object is between min and max metres above the floor.",
)
def _height(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    obj = ctx.obj(call)
    hi, lo = ctx.num(call, "max"), ctx.num(call, "min")
    if hi is None and lo is None:
        raise PredicateError("height_above_floor: give max and/or min")
    h = obj.height_above_floor
    ok = (hi is None or h <= hi) and (lo is None or h >= lo)
    return ok, f"{obj.name} is {h:.2f} m above the floor"


@_predicate(
    "near_edge",
    {"object": "variable or instance", "max_distance": "metres"},
    "The object rests on a raised surface within max_distance of that surface's edge.",
)
def _near_edge(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    obj = ctx.obj(call)
    limit = ctx.num(call, "max_distance", 0.1)
    d = obj.distance_to_edge
    if d is None or obj.on_floor:
        return False, f"{obj.name} is not on a raised surface"
    return d <= limit, f"{obj.name} is {d:.2f} m from the edge"


@_predicate(
    "child_reachable",
    {"object": "variable or instance"},
    "A small child could reach the object: its bottom at most 1.0 m up (CHILD_REACH) and not shut inside a "
    "closed container that latches (a knowledge-base 'lockable' object: a safe, a medicine cabinet); a "
    "cupboard door or a box lid a toddler opens does not keep it out. Computed from the simulated state "
    "into GraphObject.child_reachable (schema.within_child_reach).",
)
def _child_reachable(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    obj = ctx.obj(call)
    return obj.child_reachable, f"{obj.name} is {'within' if obj.child_reachable else 'out of'} a child's reach"


@_predicate(
    "inside",
    {"object": "variable or instance", "container": "variable, instance, category alternatives, or '*' for any"},
    "A relation says the object is inside the container (or inside anything, for '*').",
)
def _inside(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    obj, hit, names = _related(ctx, call, "inside", "container")
    if names is None:
        return bool(hit), f"{obj.name} is {'inside ' + hit[0] if hit else 'not inside anything'}"
    return bool(hit), f"{obj.name} is {'inside ' + hit[0] if hit else 'not inside ' + '/'.join(sorted(names))}"


@_predicate(
    "on",
    {"object": "variable or instance", "support": "variable, instance, category alternatives, or '*'"},
    "A relation says the object rests on the support.",
)
def _on(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    obj, hit, names = _related(ctx, call, "on", "support")
    if names is None:
        return bool(hit), f"{obj.name} rests on {hit[0] if hit else 'nothing'}"
    return bool(hit), f"{obj.name} is {'on ' + hit[0] if hit else 'not on ' + '/'.join(sorted(names))}"


def _related(ctx: _Ctx, call: PredicateCall, relation: str, arg: str) -> tuple[GraphObject, list[str], set[str] | None]:
    """The object, the instances it stands in ``relation`` to that ``arg`` names, and those names
    (None for ``'*'``: then every instance it stands in that relation to counts)."""
    obj = ctx.obj(call)
    related = [_base(r) for r in ctx.relations(obj.name, relation) if r]
    if str(call.args.get(arg, "*")) == "*":
        return obj, related, None
    names = set(_resolve_many(ctx, call, arg))
    return obj, [r for r in related if r in names], names


def _resolve_many(ctx: _Ctx, call: PredicateCall, arg: str) -> list[str]:
    """Instances named by an argument: a bound variable, an instance name, or category alternatives."""
    value = str(call.args[arg])
    if value.startswith("$"):
        return [ctx.name(call, arg)]
    alts = _alternatives(value)
    by_name = [a for a in alts if a in ctx._by_name]
    by_cat = [o.name for o in ctx.graph.objects if o.category in alts]
    return by_name + by_cat


@_predicate(
    "joint_open",
    {"object": "variable or instance", "label": "joint label, alternatives 'door|drawer', or '*'", "min_fraction": "0..1"},
    "Some joint of the object with a matching label is open at least min_fraction of its range.",
)
def _joint_open(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    obj = ctx.obj(call)
    wanted = _alternatives(call.args.get("label", "*"))
    limit = ctx.num(call, "min_fraction", 0.2)
    joints = [j for j in obj.joints if _label_matches(j.label, wanted)]
    if not joints:
        return False, f"{obj.name} has no {'/'.join(wanted)} joint"
    best = max(joints, key=lambda j: j.open_fraction)
    return best.open_fraction >= limit, f"{obj.name} {best.label} is {best.open_fraction:.0%} open"


@_predicate(
    "joint_closed",
    {"object": "variable or instance", "label": "joint label, alternatives, or '*'", "max_fraction": "0..1"},
    "The object has a joint with a matching label and every such joint is open at most max_fraction.",
)
def _joint_closed(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    obj = ctx.obj(call)
    wanted = _alternatives(call.args.get("label", "*"))
    limit = ctx.num(call, "max_fraction", CLOSED_TOL)
    joints = [j for j in obj.joints if _label_matches(j.label, wanted)]
    if not joints:
        return False, f"{obj.name} has no {'/'.join(wanted)} joint"
    worst = max(joints, key=lambda j: j.open_fraction)
    return worst.is_closed(limit), f"{obj.name} {worst.label} is {worst.open_fraction:.0%} open"


@_predicate(
    "near",
    {"a": "variable or instance", "b": "variable or instance", "max_distance": "metres",
     "walls_separate": "'true' or 'false' (optional, default 'false'): one of the two shut inside a closed "
                       "container the other is not in is apart"},
    "The gap between the two objects' bounding boxes is at most max_distance. With walls_separate, a "
    "container's shut walls keep them apart however close they stand (a bleach bottle locked in a safe "
    "is not among the food on the floor beside it).",
)
def _near(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    a, b = ctx.obj(call, "a"), ctx.obj(call, "b")
    limit = ctx.num(call, "max_distance", 0.3)
    gap = aabb_gap(a, b)
    if ctx.flag(call, "walls_separate"):
        wall = _shut_between(ctx, a, b)
        if wall is not None:
            return False, f"{a.name} is {gap:.2f} m from {b.name}, but {wall} is shut between them"
    return gap <= limit, f"{a.name} is {gap:.2f} m from {b.name}"


def _shut_between(ctx: _Ctx, a: GraphObject, b: GraphObject) -> str | None:
    """A closed container that holds exactly one of ``a`` and ``b`` (neither of them itself)."""
    holds_a = {_base(c) for c in ctx.relations(a.name, "inside") if c}
    holds_b = {_base(c) for c in ctx.relations(b.name, "inside") if c}
    for name in sorted((holds_a ^ holds_b) - {a.name, b.name}):
        container = ctx._by_name.get(name)
        if container is not None and _shut(container):
            return name
    return None


def _shut(container: GraphObject) -> bool:
    """Every part that encloses the container (door, drawer, lid, flap) is closed, and it has one."""
    return shut_by((j, j.value) for j in container.joints if j.encloses)


@_predicate(
    "in_walkway",
    {"object": "variable or instance"},
    "The object lies on the open floor where people walk: on the floor, not inside or under anything, "
    f"and more than {WALKWAY_CLEARANCE} m (horizontally) from every furniture or appliance; a 'blocks' "
    "relation also counts.",
)
def _in_walkway(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    obj = ctx.obj(call)
    if ctx.relations(obj.name, "blocks"):
        return True, f"{obj.name} blocks a passage"
    if not obj.on_floor:
        return False, f"{obj.name} is not on the floor"
    if ctx.relations(obj.name, "inside") or ctx.relations(obj.name, "under"):
        return False, f"{obj.name} is tucked away"
    fixtures = [
        o for o in ctx.graph.objects if o.name != obj.name and any(p in o.properties for p in ROOM_FIXTURES)
    ]
    close = [o for o in fixtures if aabb_gap(obj, o, horizontal=True) <= WALKWAY_CLEARANCE]
    if close:
        return False, f"{obj.name} lies beside {close[0].name}, out of the way"
    return True, f"{obj.name} lies in the open walkway"


@_predicate(
    "has_state",
    {"object": "variable or instance", "state": "a state word, or alternatives 'a|b' (any of them)"},
    "The instance shows the state (GraphObject.states: contains_water, wet, lit, handle_out, face_down).",
)
def _has_state(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    obj = ctx.obj(call)
    return _any_of(obj.name, _alternatives(call.args.get("state", "")), obj.states)


@_predicate(
    "is_on",
    {"object": "variable or instance"},
    f"The object is switched on: a knob, switch, button, dial or tap of it is at least {ON_FRACTION:.0%} "
    "open, or, for a thing with no such control, its states say on or lit.",
)
def _is_on(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    obj = ctx.obj(call)
    controls = [j for j in obj.joints if part_labels.is_switch(j.label)]  # a tap runs water
    if controls:
        best = max(controls, key=lambda j: j.open_fraction)
        return best.open_fraction >= ON_FRACTION, f"{obj.name} {best.label} is {best.open_fraction:.0%} on"
    lit = [s for s in ON_STATES if s in obj.states]
    return bool(lit), f"{obj.name} is {lit[0] if lit else 'off (no control, not lit)'}"


@_predicate("room_is", {"room": "room name or alternatives 'a|b'"}, "The scene's room is one of the given rooms.")
def _room_is(ctx: _Ctx, call: PredicateCall) -> tuple[bool, str]:
    wanted = _alternatives(call.args.get("room", ""))
    return ctx.graph.room in wanted, f"the room is a {ctx.graph.room}"


# --------------------------------------------------------------------------- evaluation


def variables_of(call: PredicateCall) -> list[str]:
    return [v for v in call.args.values() if isinstance(v, str) and v.startswith("$")]


def evaluate(call: PredicateCall, graph: SceneGraph, bindings: dict[str, str] | None = None) -> PredicateResult:
    """Evaluate one call (applying ``negate``) on a scene graph; raises PredicateError for bad calls."""
    impl = _IMPLS.get(call.name)
    if impl is None:
        raise PredicateError(f"unknown predicate '{call.name}' (known: {', '.join(sorted(_IMPLS))})")
    holds, why = impl(_Ctx(graph, bindings or {}), call)
    if call.negate:
        holds = not holds
    return PredicateResult(call=call, holds=holds, explanation=why)


def evaluate_all(calls: list[PredicateCall], graph: SceneGraph, bindings: dict[str, str]) -> list[PredicateResult]:
    return [evaluate(c, graph, bindings) for c in calls]


def all_hold(calls: list[PredicateCall], graph: SceneGraph, bindings: dict[str, str]) -> bool:
    return all(r.holds for r in evaluate_all(calls, graph, bindings))


def match_class(hc, graph: SceneGraph, *, fixed: dict[str, str] | None = None) -> list[Match]:
    """Every binding of ``hc``'s precondition variables to distinct scene objects that satisfies them all.

    Variables are bound in first-use order, and each precondition is checked as soon as its
    variables are bound, so non-matching branches are cut early (scenes have tens of objects).
    ``fixed`` pre-binds variables (e.g. the planner already knows ``$hazard``).
    """
    order = [v for v in hc.variable_names() if v not in (fixed or {})]
    staged: list[list[PredicateCall]] = [[] for _ in range(len(order) + 1)]
    for call in hc.preconditions:
        needed = [v for v in variables_of(call) if v in order]
        staged[max((order.index(v) + 1 for v in needed), default=0)].append(call)

    matches: list[Match] = []
    names = [o.name for o in graph.objects]

    def check(calls: list[PredicateCall], bindings: dict[str, str], why: list[str]) -> bool:
        for call in calls:
            result = evaluate(call, graph, bindings)
            if not result.holds:
                return False
            why.append(result.explanation)  # already describes the actual state, negated or not
        return True

    def extend(depth: int, bindings: dict[str, str], why: list[str]) -> None:
        if depth == len(order):
            matches.append(Match(bindings=dict(bindings), explanation="; ".join(why), score=hc.severity))
            return
        var = order[depth]
        for name in names:
            if name in bindings.values():
                continue
            bindings[var] = name
            local = list(why)
            if check(staged[depth + 1], bindings, local):
                extend(depth + 1, bindings, local)
            del bindings[var]

    start = dict(fixed or {})
    why0: list[str] = []
    if check(staged[0], start, why0):
        extend(0, start, why0)
    return matches


def bind_others(hc, graph: SceneGraph, bindings: dict[str, str]) -> dict[str, str]:
    """``bindings`` plus the class's other precondition variables (the lit burner a towel lies on),
    bound by matching the class with the given ones fixed; unchanged when nothing matches."""
    fixed = {v: n for v, n in bindings.items() if v in hc.variable_names()}
    missing = [v for v in hc.variable_names() if v not in fixed]
    if not missing:
        return dict(bindings)
    try:
        matches = match_class(hc, graph, fixed=fixed)
    except PredicateError:
        return dict(bindings)
    return {**bindings, **{v: matches[0].bindings[v] for v in missing}} if matches else dict(bindings)


def iter_calls(hc) -> itertools.chain:
    return itertools.chain(hc.preconditions, hc.success)
