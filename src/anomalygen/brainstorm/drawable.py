"""What brainstorming may draw: the classes (and, per class, the objects and placements) that can be
built and fixed today.

The knowledge base composes classes over objects and places the builder or the robot may not have
yet (a sink that holds water, a skill to turn a pan handle). Proposing those would make tasks that
fail later, so the engine draws from the intersection of the composed space with what the asset
catalogue holds (``assets``), the states the builder sets up (``scene/capabilities``; it builds every
placement relation of ``schema/placement.py``) and the recipe actions the planner can carry out
(``plan/planner.plannable``). Nothing is listed by hand: a new asset, relation kind, state or skill
becomes drawable as soon as it exists.
"""

from __future__ import annotations

import functools

from anomalygen.knowledge import HazardClass, KnowledgeBase
from anomalygen.knowledge.households import load_households
from anomalygen.schema import Placement, part_labels


@functools.cache
def catalogue() -> frozenset[str]:
    """Every name the asset catalogue can build."""
    from anomalygen.scene.asset_choice import catalogue_names

    return frozenset(catalogue_names())


def relation_variable(hc: HazardClass) -> str | None:
    """The variable a composed class's placement parent fills (the burner in ``on:Stove``), if any."""
    if hc.composition is None or hc.composition.legacy:
        return None
    from anomalygen.knowledge.mechanisms import load_mechanisms

    place = load_mechanisms().places.get(hc.composition.place)
    return place.relation.variable if place is not None and place.relation is not None else None


def needed_states(kb: KnowledgeBase, hc: HazardClass) -> dict[str, list[str]]:
    """Instance states, by variable, a scene of ``hc`` must show."""
    if hc.composition is None:
        return {}
    from anomalygen.knowledge.mechanisms import load_mechanisms, setup_states

    return setup_states(load_mechanisms(), hc)


def state_shown(kb: KnowledgeBase, obj: str, state: str) -> bool:
    """Can a scene show ``obj`` in ``state``: the builder sets it up, or every such object shows it."""
    from anomalygen.scene.capabilities import can_show

    info = kb.objects.get(obj)
    return can_show(state) or (info is not None and state in info.states)


@functools.cache
def asset_parts(obj: str) -> frozenset[str]:
    """The knowledge-base joint labels the catalogue's asset of ``obj`` has (a knob, a door)."""
    from anomalygen.assets.core import generate
    from anomalygen.schema.part_labels import canonical

    return frozenset(canonical(j.label) for j in generate(obj, 0).joints)


def has_part(obj: str, part: str) -> bool:
    """Does the asset have a joint for ``part`` ('knob|switch': either; a button is a switch)?"""
    wanted = part.split("|")
    either = (part_labels.KNOB, part_labels.SWITCH)
    if any(w in either for w in wanted):
        wanted = [*wanted, *either]
    return bool(set(wanted) & asset_parts(obj))


def _part_ok(hc: HazardClass, variable: str | None, obj: str) -> bool:
    art = hc.articulation
    return art is None or variable is None or art.variable != variable or has_part(obj, art.part)


def buildable_placement(placement: Placement) -> bool:
    """Every relation kind is built (``scene/placement.py``); one to another object needs that object's
    asset, and inside it an interior."""
    parent = placement.other
    if parent is None:
        return True
    return parent in catalogue() and (placement.relation != "inside" or has_interior(parent))


@functools.cache
def has_interior(obj: str) -> bool:
    from anomalygen.assets.core import generate

    return bool(generate(obj, 0).cavities)


INTERIOR_VARIANTS = 4  # variants of a holder looked at for its roomiest interior


@functools.cache
def _variants(kb: KnowledgeBase, obj: str, end: int) -> tuple:
    """``obj``'s first INTERIOR_VARIANTS assets at the small (``end`` 0) or large (1) end of its size range."""
    from anomalygen.assets.core import generate
    from anomalygen.scene.asset_choice import size_bounds

    size = size_bounds(kb, obj)[end]
    return tuple(generate(obj, seed, size=size) for seed in range(INTERIOR_VARIANTS))


@functools.cache
def _roomiest(kb: KnowledgeBase, obj: str, measure) -> float:
    """The most ``measure`` (the builder's ``cavity_cap`` for an ``inside:obj`` placement, its
    ``container_room`` for putting things away in ``obj``) gives over ``obj``'s variants at its
    largest size; 0 without an interior."""
    return max((measure(a) for a in _variants(kb, obj, 1) if a.cavities), default=0.0)


def containers_for(kb: KnowledgeBase, hc: HazardClass, hazard: str) -> list[str]:
    """The containers the fix may put ``hazard`` away in (``kb.safe_containers_for``) that have an
    asset with room for it: a 1 m extension cord lies straight and no safe holds it."""
    from anomalygen.scene.asset_choice import container_room, size_bounds

    least = size_bounds(kb, hazard)[0]
    return [c for c in kb.safe_containers_for(hc, hazard)
            if c in catalogue() and _roomiest(kb, c, container_room) >= least]


def fits_inside(kb: KnowledgeBase, hazard: str, holder: str) -> bool:
    """Can the smallest ``hazard`` go inside the roomiest ``holder``? A 0.15 m spoon never fits a
    toaster's 2 cm slot, and a task drawn that way fails every build."""
    from anomalygen.scene.asset_choice import cavity_cap, size_bounds

    return size_bounds(kb, hazard)[0] <= _roomiest(kb, holder, cavity_cap)


@functools.cache
def _largest_surface(kb: KnowledgeBase, obj: str) -> tuple[float, float]:
    """(long, short) sides of the roomiest top ``obj``'s variants offer at its largest size (a stair
    tread, a hob); (0, 0) without one."""
    tops = [tuple(sorted((2 * float(h) for h in s.half_size), reverse=True))
            for a in _variants(kb, obj, 1) for s in a.surfaces]
    return max(tops, key=lambda t: t[0] * t[1], default=(0.0, 0.0))


@functools.cache
def _least_footprint(kb: KnowledgeBase, obj: str) -> tuple[float, float]:
    """(long, short) footprint of ``obj`` at its smallest size, the most compact of a few variants: a
    cord wanders, so its footprint is not its length alone."""
    feet = []
    for a in _variants(kb, obj, 0):
        (x0, y0, _), (x1, y1, _) = a.aabb
        feet.append(tuple(sorted((float(x1 - x0), float(y1 - y0)), reverse=True)))
    return min(feet, key=lambda f: f[1])


TOP_MARGIN = 0.9  # of a top's longest side a thing may span: the layout keeps clear of its rims


def fits_on(kb: KnowledgeBase, hazard: str, placement: Placement) -> bool:
    """Can the smallest ``hazard`` lie on the top the placement puts it on? A 1 m extension cord fits
    no side table or stair tread, and a task drawn that way fails every build. Placements on the
    floor, or in or near another object, are left to the layout."""
    from anomalygen.scene.furniture import TOPS, largest_top

    if placement.relation in ("on", "at_edge") and placement.support in TOPS:
        top = largest_top(placement.support)
    elif placement.relation == "on" and placement.other is not None and placement.other in catalogue():
        top = _largest_surface(kb, placement.other)
        if top[0] == 0.0:
            return True  # no surface recorded: the layout decides
    else:
        return True
    long, short = _least_footprint(kb, hazard)
    return long <= TOP_MARGIN * top[0] and short <= TOP_MARGIN * top[1]


def hazards_for(kb: KnowledgeBase, hc: HazardClass) -> list[str]:
    """The class's hazard candidates that have an asset, can show the states asked of them and, when
    the fix puts them away, fit one of its containers."""
    states = needed_states(kb, hc).get(hc.hazard_variable, [])
    stored = bool(hc.default_containers) and any("$container" in str(step.args) for step in hc.recipe)
    return [o for o in kb.hazard_candidates(hc) if o in catalogue() and o not in hc.not_drawn
            and all(state_shown(kb, o, s) for s in states)
            and _part_ok(hc, hc.hazard_variable, o) and (not stored or containers_for(kb, hc, o))]


_INTRINSIC = ("has_property", "category_is")


@functools.lru_cache(maxsize=8)
def _left_out_hazards(kb: KnowledgeBase) -> frozenset[str]:
    """Objects that are a hazard of some class wherever they are left out of a container.

    Such a class's preconditions name only its own object: what the object is, that it is not inside
    something and, at most, a height band a table or counter falls in (leftovers, a knife, bleach).
    """
    out: set[str] = set()
    for hc in kb.hazard_classes.values():
        calls = hc.preconditions
        named = {v for c in calls for v in c.args.values() if isinstance(v, str) and v.startswith("$")}
        left_out = any(c.name == "inside" and c.negate for c in calls)
        rest = [c for c in calls if not (c.name in _INTRINSIC or (c.name == "inside" and c.negate)
                                         or c.name == "height_above_floor")]
        if named == {hc.hazard_variable} and left_out and not rest:
            out.update(kb.hazard_candidates(hc))
    return frozenset(out)


def harmless_first(kb: KnowledgeBase, objects: list[str]) -> list[str]:
    """``objects`` without those that would be a second hazard of their own, unless none is left.

    The object a hazard is beside (the food the bleach stands among) is scenery, not a fault: left-out
    leftovers would make a second hazard, whose fix (a fridge) the scene need not hold.
    """
    bad = _left_out_hazards(kb)
    return [o for o in objects if o not in bad] or objects


def placements_for(kb: KnowledgeBase, hc: HazardClass, hazard: str) -> list[Placement]:
    """The class's placements for ``hazard`` that the builder can set up with objects it has."""
    var = relation_variable(hc)
    states = needed_states(kb, hc).get(var, []) if var else []
    out = []
    for p in kb.placements_for(hc, hazard):
        if not buildable_placement(p):
            continue
        parent = p.other
        if p.relation == "inside" and not fits_inside(kb, hazard, parent):
            continue
        if p.relation == "on" and parent is not None and not load_households().holds_on_top(parent):
            continue  # a space heater's grille holds no towel: the builder finds no top to set it on
        if not fits_on(kb, hazard, p):
            continue
        if parent is not None and var is not None and not (all(state_shown(kb, parent, s) for s in states)
                                                           and _part_ok(hc, var, parent)):
            continue
        out.append(p)
    return out


_WHY_NOT: dict[tuple[int, str], str | None] = {}


def drawable(kb: KnowledgeBase, hc: HazardClass) -> bool:
    """Can a proposal of ``hc`` be built and its fix planned with today's assets, builder and skills?"""
    return why_not_drawable(kb, hc) is None


def why_not_drawable(kb: KnowledgeBase, hc: HazardClass) -> str | None:
    """None when ``hc`` can be drawn, else what is missing (a skill, an asset, a placement)."""
    key = (id(kb), hc.id)
    if key not in _WHY_NOT:
        _WHY_NOT[key] = _why_not(kb, hc)
    return _WHY_NOT[key]


def _why_not(kb: KnowledgeBase, hc: HazardClass) -> str | None:
    from anomalygen.plan.planner import plannable

    if hc.undrawn_because:
        return f"{hc.id} is not drawn yet: {hc.undrawn_because}"

    missing = [step.action for step in hc.recipe if not plannable(step.action)]
    if missing:
        return f"no skill for {missing[0]} yet: {hc.id}'s fix needs it"
    cat = catalogue()
    if hc.default_containers and not any(c in cat for c in hc.default_containers):
        return f"no asset for any of {hc.id}'s containers ({', '.join(hc.default_containers)})"
    if hc.default_supports and not any(s in cat for s in hc.default_supports):
        return f"no asset for any of {hc.id}'s supports ({', '.join(hc.default_supports)})"
    var = relation_variable(hc)
    others = [v for v in hc.variable_names() if v not in (hc.hazard_variable, var)]
    for v in others:  # a co-object plays it (the fume source of a stuffy room)
        if v != "$target" and not [o for o in kb.static_candidates(hc, v) if o in cat]:
            return f"no asset can play {hc.id}'s {v}"
    if not any(placements_for(kb, hc, h) for h in hazards_for(kb, hc)):
        return f"no object of {hc.id} with an asset has a placement (states, room inside) the builder can set up"
    return None
