"""Bind a fix's role variables from what the robot perceives, not from the builder's bindings.

A detection names the object at fault and a hazard class. The recipe of that class also needs a
container (put the knife away), a support (lay the cable on a shelf) or the object a precondition
relates to (the window of a stuffy room). The robot chooses them itself, here, from the scene graph:

- variables in the class's preconditions come from matching the class on the perceived graph with
  the object at fault fixed (the same reading of the scene that made the detection);
- ``$container``: the nearest object of a kind the class puts such things in (the knowledge base's
  containers for the class and object) that the object fits and the arm can reach, preferring one
  that ends the hazard once shut (``ends_hazard``), then one whose lid has nothing over it;
- ``$support``: the nearest surface of a kind the class lays things on, preferring one with nothing
  over it and room to leave the object clear of its edges.
"""

from __future__ import annotations

import math

from anomalygen.errors import ItemFailed
from anomalygen.schema import (
    LATCHING_PROPERTY,
    LID_LABELS,
    GraphObject,
    Relation,
    SceneGraph,
    within_child_reach,
)

REACH_BOTTOM_M = 1.2  # a container standing higher than this is out of the arm's comfortable reach
AFTER_PLACE_LIFT_M = 0.02  # predicted height of a placed object above its container's base
REACH_TOP_M = 1.6  # a surface whose top is higher than this is out of the arm's comfortable reach
STABLE_TOPS = ("Table", "counter", "shelf", "StorageFurniture")  # categories with a flat, level top board
EDGE_ROOM_M = 0.15  # a support should leave the object this far from its edges on both sides


def bind_fix(hc, fault: str, graph: SceneGraph, kb, given: dict[str, str] | None = None) -> dict[str, str]:
    """Every role variable of ``hc``'s recipe bound to a perceived object; ItemFailed when one cannot be.

    ``given`` binds some roles already (``{"$container": "drawer_0"}``: an agent's own choice); the
    others are chosen here around them."""
    from anomalygen.knowledge.predicates import PredicateError, match_class

    names = {o.name: o for o in graph.objects}
    if fault not in names:
        raise ItemFailed(f"the detected object {fault!r} is not in the scene")
    bindings = {hc.hazard_variable: fault, **(given or {})}
    try:
        matches = match_class(hc, graph, fixed=dict(bindings))
    except PredicateError:
        matches = []
    if matches:
        bindings.update(sorted(matches[0].bindings.items()))
    for var in hc.recipe_variable_names():
        if var in bindings:
            continue
        if var == "$container":
            bindings[var] = choose_container(hc, names[fault], graph, kb)
        elif var == "$support":
            bindings[var] = choose_support(hc, names[fault], graph)
        elif var == "$target":
            bindings[var] = fault
        else:
            raise ItemFailed(f"{hc.id}: nothing in the scene can play {var}")
    return bindings


def choose_container(hc, obj: GraphObject, graph: SceneGraph, kb) -> str:
    kinds = kb.containers_for(hc, obj.category)
    fits = [o for o in graph.objects if o.name != obj.name and o.category in kinds and _fits(obj, o)
            and o.height_above_floor <= REACH_BOTTOM_M]  # a tall fridge is reachable: its lower shelves are
    if not fits:
        raise ItemFailed(f"no reachable container for {obj.name} in the scene (wanted: {', '.join(kinds) or 'none'})")
    classes = list(kb.hazard_classes.values())
    safe = [o for o in fits if ends_hazard(classes, obj, o, graph)]  # no hazard of any kind afterwards
    ending = safe or [o for o in fits if ends_hazard([hc], obj, o, graph)] or fits
    # a lid opens upwards: under a wall shelf a bin's lid stops half open and the carton lands on it
    covered = {r.subject for r in graph.relations if r.predicate == "under"}
    free = [o for o in ending if o.name not in covered or not any(j.label in LID_LABELS for j in o.joints)]
    return _nearest(obj, free or ending)


def ends_hazard(classes, obj: GraphObject, container: GraphObject, graph: SceneGraph) -> bool:
    """Would none of ``classes`` hold for ``obj`` once it is shut inside ``container``?

    Why: "inside a box" ends a litter hazard but not a choking one when the box is an open carton on
    the floor, and shears stored in a low open box are a child's hazard instead. The robot predicts
    the scene after its fix (the object low inside the container, the container's doors, drawers and
    lids shut) and checks the classes' own preconditions on it.
    """
    from anomalygen.knowledge.predicates import PredicateError, match_class

    bottom = container.height_above_floor + AFTER_PLACE_LIFT_M
    latches = any(j.encloses for j in container.joints) and LATCHING_PROPERTY in container.properties
    moved = obj.model_copy(update={
        "position": [container.position[0], container.position[1], bottom + obj.size[2] / 2],
        "height_above_floor": bottom, "on_floor": False, "distance_to_edge": None,
        "child_reachable": within_child_reach(bottom, latches),
    })
    after = graph.model_copy(update={
        "objects": [moved if o.name == obj.name else o for o in graph.objects],
        "relations": [r for r in graph.relations if obj.name not in (r.subject, r.object)]
        + [Relation(subject=obj.name, predicate="inside", object=container.name)],
    })
    for hc in classes:
        try:
            if match_class(hc, after, fixed={hc.hazard_variable: obj.name}):
                return False
        except PredicateError:
            continue
    return True


def choose_support(hc, obj: GraphObject, graph: SceneGraph) -> str:
    """The nearest perceived surface of a kind the class lays things on; when the scene has none of
    those, the nearest stable top of any kind (a table, counter, shelf or cabinet) that is within
    reach and wider than the object: a phone can go on a counter when the room has no desk."""
    kinds = set(hc.default_supports)
    cands = [o for o in graph.objects if o.name != obj.name and o.category in kinds]
    if not cands:
        cands = [o for o in graph.objects if o.name != obj.name and o.category in STABLE_TOPS
                 and o.position[2] + o.size[2] / 2 <= REACH_TOP_M and min(o.size[:2]) > max(obj.size[:2])]
    if not cands:
        raise ItemFailed(f"no surface for {obj.name} in the scene (wanted: {', '.join(sorted(kinds)) or 'none'})")
    # better a top with nothing over it (the arm cannot lower a pan under a wall shelf) and room to
    # leave the object clear of its edges (else it is a heavy thing at an edge once put there)
    covered = {r.subject for r in graph.relations if r.predicate == "under"}
    roomy = [o for o in cands if min(o.size[:2]) >= max(obj.size[:2]) + 2 * EDGE_ROOM_M]
    for pool in ([o for o in roomy if o.name not in covered], [o for o in cands if o.name not in covered], roomy):
        if pool:
            return _nearest(obj, pool)
    return _nearest(obj, cands)


def _fits(obj: GraphObject, container: GraphObject) -> bool:
    """Loose test on bounding boxes: the object's longest side within the container's longest side, and
    its footprint within the container's (the suction cup lowers it lying as it lay: a flat bag wider
    than a bin does not pass the bin's mouth however tall the bin is)."""
    return max(obj.size) < max(container.size) and max(obj.size[:2]) < max(container.size[:2])


def _nearest(obj: GraphObject, cands: list[GraphObject]) -> str:
    return min(cands, key=lambda o: (math.dist(obj.position[:2], o.position[:2]), o.name)).name
