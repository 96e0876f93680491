"""Are the knowledge base's hazard classes discriminative? A sweep over minimal synthetic scene graphs.

For every class, every catalogue object the knowledge base allows as its hazard, and every placement
it allows for that object, build the smallest realistic scene graph in which that hazard is set up
(a kitchen's counter, table, closed fridge and closed cabinet, plus the hazard, plus optional benign
clutter) and check that the rule detector names that object and class at rank 1. A failure means two
classes' preconditions overlap without a severity that settles it, or a class cannot fire at all —
a knowledge-base problem found without building a single MuJoCo scene. Used by the tests and by
``benchmarks/bench_detect.py``.
"""

from __future__ import annotations

from dataclasses import dataclass

from anomalygen.schema import (
    CHILD_REACH,
    DOOR,
    DRAWER,
    GraphObject,
    JointState,
    Placement,
    Relation,
    SceneGraph,
    part_labels,
)

#: Top-surface heights (m) per support kind, inside the knowledge base's SUPPORT_HEIGHTS ranges.
SURFACE_TOP = {"table": 0.75, "counter": 0.9, "shelf": 1.4, "low_table": 0.42}
EDGE_GAP = 0.04  # distance to the edge for at_edge placements (m)
CLUTTER_X = (0.08, 0.64, -0.2, 1.2, 0.36, 0.92)  # m: clutter spots along the counter (x -0.4..1.4), 0.28 m apart


def _obj(name: str, category: str, props: list[str], *, pos, size, height: float, on_floor: bool,
         edge: float | None = None, reach: bool | None = None, joints: list[JointState] | None = None) -> GraphObject:
    return GraphObject(name=name, category=category, properties=props, position=list(pos), size=list(size),
                       height_above_floor=height, on_floor=on_floor, distance_to_edge=edge,
                       child_reachable=(height <= CHILD_REACH) if reach is None else reach, joints=joints or [])


def _joint(name: str, label: str, fraction: float) -> JointState:
    return JointState(name=name, label=label, type="hinge", value=1.5 * fraction, range=(0.0, 1.5), closed_value=0.0)


def _props(kb, category: str) -> list[str]:
    info = kb.objects.get(category)
    return list(info.properties) if info else []


def furniture(kb) -> list[GraphObject]:
    """The room every synthetic scene stands in: nothing here may fire a class by itself."""
    return [
        _obj("counter_0", "counter", _props(kb, "counter"), pos=(0.5, 1.6, 0.45), size=(1.8, 0.6, 0.9), height=0.0, on_floor=True),
        _obj("table_0", "Table", _props(kb, "Table"), pos=(1.6, 0.5, 0.375), size=(1.0, 0.8, 0.75), height=0.0,
             on_floor=True, joints=[_joint("table_0_drawer", DRAWER, 0.0)]),
        _obj("refrigerator_0", "Refrigerator", _props(kb, "Refrigerator"), pos=(-0.6, 1.6, 0.9), size=(0.7, 0.7, 1.8),
             height=0.0, on_floor=True, joints=[_joint("refrigerator_0_door", DOOR, 0.0)]),
        _obj("storage_0", "StorageFurniture", _props(kb, "StorageFurniture"), pos=(2.6, 1.6, 0.45), size=(0.8, 0.5, 0.9),
             height=0.0, on_floor=True, joints=[_joint("storage_0_door", DOOR, 0.0)]),
    ]


def clutter(kb, n: int) -> tuple[list[GraphObject], list[Relation]]:
    """``n`` benign objects (no hazard property) resting along the counter, away from its edges and more
    than any class's ``near`` limit from the hazards (which stand by the table and the room's door side):
    a blanket is benign alone but not beside a hot iron, and a loaf not beside a cleaner."""
    names = sorted(kb.benign_objects())
    objs, rels = [], []
    spots = [(x, 1.6, 0.9, "counter_0") for x in CLUTTER_X]
    for i in range(n):
        cat = names[(7 * i) % len(names)]
        x, y, top, support = spots[i % len(spots)]
        name = f"{cat.lower()}_c{i}"
        objs.append(_obj(name, cat, _props(kb, cat), pos=(x, y, top + 0.05), size=(0.1, 0.1, 0.1), height=top,
                         on_floor=False, edge=0.2))
        rels.append(Relation(subject=name, predicate="on", object=support))
    return objs, rels


#: Scenes of one class that are, by design, first a scene of another class on the same set-up, the
#: severities settling it: (class, the placement's other object or None) -> (class ranked first, whose
#: object it names: "hazard" or "other").
RANKED_FIRST_BY_DESIGN: dict[tuple[str, str | None], tuple[str, str]] = {
    # a hot iron face down is a heat tool left on: switching it off, a fix the robot has, ends both
    ("stand_iron_upright", None): ("switch_off_heat_tool", "hazard"),
    # paper by a heater or an iron that is on is the heater left on beside something that burns (0.96 over 0.95)
    ("clear_burning_risk_near_heat_source", "iron"): ("switch_off_heater_near_fabric", "other"),
    ("clear_burning_risk_near_heat_source", "SpaceHeater"): ("switch_off_heater_near_fabric", "other"),
}


@dataclass(frozen=True)
class Case:
    hazard_class: str
    obj: str
    placement: Placement
    graph: SceneGraph
    instance: str
    ranked_first: str = ""  # the class the detector must name first: hazard_class unless set by design


def _expected(hc_id: str, placement: Placement, inst: str) -> tuple[str, str]:
    """(instance, class) the detector must rank first on a case's scene (RANKED_FIRST_BY_DESIGN)."""
    parent = placement.other or None
    first, whose = RANKED_FIRST_BY_DESIGN.get((hc_id, parent), (hc_id, "hazard"))
    return (f"{parent.lower()}_0" if whose == "other" and parent else inst), first


def _hazard_objects(kb, hc, obj: str, placement: Placement) -> tuple[list[GraphObject], list[Relation], str]:
    name = f"{obj.lower()}_0"
    props = _props(kb, obj)
    if hc.about_target and hc.articulation is not None:
        label = kb.articulation_part(hc, obj) or part_labels.alternatives(hc.articulation.part)[0]
        frac = 0.8 if hc.articulation.initial_state in ("open", "on") else 0.0
        objs = [_obj(name, obj, props, pos=(1.0, -0.8, 0.5), size=(0.6, 0.6, 1.0), height=0.0, on_floor=True,
                     joints=[_joint(f"{name}_{label}", label, frac)])]
        extra_calls = [c for c in hc.preconditions if c.args.get("object") == "$hazard"]
        if extra_calls:  # e.g. ventilating a kitchen needs something hot on the stove-top
            hot = next(n for n in sorted(kb.objects) if "hot" in _props(kb, n))
            objs.append(_obj(f"{hot.lower()}_0", hot, _props(kb, hot), pos=(0.5, 1.6, 0.95), size=(0.2, 0.2, 0.1),
                             height=0.9, on_floor=False, edge=0.25))
        return objs, [], name
    if placement.support == "floor":
        return [_obj(name, obj, props, pos=(1.0, -0.8, 0.03), size=(0.1, 0.1, 0.06), height=0.0, on_floor=True)], [], name
    if placement.relation == "inside":
        parent = placement.other
        info = kb.objects.get(parent)
        if info is not None and info.supports and "floor" not in info.supports:
            # a counter-top appliance (a microwave): it stands on the counter, door shut, the item inside
            holder = f"{parent.lower()}_0"
            box = _obj(holder, parent, _props(kb, parent), pos=(0.9, 1.6, 1.05), size=(0.5, 0.4, 0.3), height=0.9,
                       on_floor=False, edge=0.1, joints=[_joint(f"{holder}_door", DOOR, 0.0)])
            o = _obj(name, obj, props, pos=(0.9, 1.6, 0.95), size=(0.18, 0.03, 0.02), height=0.92, on_floor=False)
            return [box, o], [Relation(subject=name, predicate="inside", object=holder),
                              Relation(subject=holder, predicate="on", object="counter_0")], name
        holder = "refrigerator_0" if parent == "Refrigerator" else "storage_0"
        o = _obj(name, obj, props, pos=(-0.6, 1.6, 0.5), size=(0.1, 0.1, 0.06), height=0.5, on_floor=False, reach=False)
        return [o], [Relation(subject=name, predicate="inside", object=holder)], name
    top = SURFACE_TOP.get(placement.support, 0.75)  # on or near another object: at a table's height
    edge = EDGE_GAP if placement.relation == "at_edge" else 0.3
    o = _obj(name, obj, props, pos=(1.6, 0.5, top + 0.03), size=(0.1, 0.1, 0.06), height=top, on_floor=False, edge=edge,
             reach=top <= CHILD_REACH)
    support = "counter_0" if placement.support == "counter" else "table_0"
    return [o], [Relation(subject=name, predicate="on", object=support)], name


PARENT_GAP = 0.1  # m between a 'near:<name>' hazard and that object, inside every class's near: limit
SMALL_PARENT = 0.4  # m: a parent whose largest size is below this is a thing, not furniture (a magazine)


def _parent(kb, parent: str) -> GraphObject:
    """The object a composed placement names: furniture (the crib in ``near:Crib``) stands on the floor, a
    small thing (the apple in ``near:apple``) on a shelf out of a child's reach, so only the class's own
    mechanism is set up."""
    info = kb.objects.get(parent)
    if info is None or info.size_range[1] >= SMALL_PARENT:
        return _obj(f"{parent.lower()}_0", parent, _props(kb, parent), pos=(1.0, -0.8, 0.45), size=(0.6, 0.6, 0.9),
                    height=0.0, on_floor=True)
    top = SURFACE_TOP["shelf"]
    return _obj(f"{parent.lower()}_0", parent, _props(kb, parent), pos=(1.0, -0.8, top + 0.05), size=(0.2, 0.2, 0.1),
                height=top, on_floor=False, edge=0.2)


def _composed_objects(kb, hc, obj: str, placement: Placement) -> tuple[list[GraphObject], list[Relation], str] | None:
    """A composed class's hazard with the other object its placement names (the crib beside a cable, the
    sink a power strip lies in); None for a placement without one (the plain builder's spots)."""
    kind, parent = placement.relation, placement.other
    if not parent or (kind == "inside" and parent in ("Refrigerator", "StorageFurniture")):
        return None
    other = _parent(kb, parent)
    name, props = f"{obj.lower()}_0", _props(kb, obj)
    top = other.position[2] + other.size[2] / 2
    x, y = other.position[0], other.position[1]
    if kind == "on":
        o = _obj(name, obj, props, pos=(x, y, top + 0.03), size=(0.1, 0.1, 0.06), height=top, on_floor=False, edge=0.2)
        return [other, o], [Relation(subject=name, predicate="on", object=other.name)], name
    if kind == "inside":
        o = _obj(name, obj, props, pos=(x, y, top / 2), size=(0.1, 0.1, 0.06), height=top / 2, on_floor=False)
        return [other, o], [Relation(subject=name, predicate="inside", object=other.name)], name
    ox, base = x + other.size[0] / 2 + PARENT_GAP + 0.05, other.height_above_floor
    o = _obj(name, obj, props, pos=(ox, y, base + 0.03), size=(0.1, 0.1, 0.06), height=base, on_floor=other.on_floor,
             edge=None if other.on_floor else 0.2)
    return [other, o], [], name


def _set_up(kb, hc, objs: list[GraphObject], inst: str, placement: Placement) -> list[GraphObject]:
    """What a composed class's scene must show beyond its objects: each object's own states (a candle is
    lit), the mechanism's set-up states (a sink holds water), and the control its fix works left on."""
    from anomalygen.knowledge.mechanisms import load_mechanisms, setup_states

    ms = load_mechanisms()
    place = ms.places.get(hc.composition.place)
    relvar = place.relation.variable if place is not None and place.relation is not None else None
    parent = placement.other
    names = {hc.hazard_variable: inst}
    if relvar and parent:
        names[relvar] = f"{parent.lower()}_0"
    states = {names[v]: list(s) for v, s in setup_states(ms, hc).items() if v in names}
    for call in hc.preconditions:  # switched on: by its control when the fix works one, else its states
        var = call.args.get("object")
        if call.name == "is_on" and not call.negate and var in names and (hc.articulation is None or hc.articulation.variable != var):
            states.setdefault(names[var], []).append("on")
    art = hc.articulation
    out = []
    for o in objs:
        info = kb.objects.get(o.category)
        extra = [*(info.states if info else []), *states.get(o.name, [])]
        update: dict = {"states": sorted({*o.states, *extra})}
        if art is not None and names.get(art.variable) == o.name and not o.joints:
            label = part_labels.alternatives(art.part)[0]
            frac = 0.8 if art.initial_state in ("open", "on") else 0.0
            update["joints"] = [_joint(f"{o.name}_{label}", label, frac)]
        out.append(o.model_copy(update=update))
    return out


def _objects(kb, hc, obj: str, placement: Placement) -> tuple[list[GraphObject], list[Relation], str]:
    if hc.composition is None or hc.composition.legacy:
        return _hazard_objects(kb, hc, obj, placement)
    objs, rels, inst = _composed_objects(kb, hc, obj, placement) or _hazard_objects(kb, hc, obj, placement)
    return _set_up(kb, hc, objs, inst, placement), rels, inst


def cases(kb, *, n_clutter: int = 0) -> list[Case]:
    out = []
    extra, extra_rels = clutter(kb, n_clutter)
    for hc in sorted(kb.hazard_classes.values(), key=lambda h: h.id):
        for obj in kb.hazard_candidates(hc):
            for placement in kb.placements_for(hc, obj):
                objs, rels, inst = _objects(kb, hc, obj, placement)
                graph = SceneGraph(scene_id=f"{hc.id}-{obj}-{placement}", room="kitchen",
                                   objects=furniture(kb) + objs + extra, relations=rels + extra_rels)
                inst, first = _expected(hc.id, placement, inst)
                out.append(Case(hc.id, obj, placement, graph, inst, first))
    return out


def sweep(kb=None, *, n_clutter: int = 0, k: int = 3) -> dict:
    """Top-1/top-k accuracy of the rule detector over every synthetic case, with the failures."""
    from anomalygen.detect.rules import RuleDetector

    if kb is None:
        from anomalygen.knowledge import load_kb

        kb = load_kb()
    det = RuleDetector(kb)
    all_cases = cases(kb, n_clutter=n_clutter)
    top1 = topk = 0
    failures = []
    for c in all_cases:
        got = [(h.target_object, h.hazard_class) for h in det.detect(c.graph, k)]
        want = (c.instance, c.ranked_first or c.hazard_class)
        top1 += bool(got) and got[0] == want
        topk += want in got
        if not got or got[0] != want:
            failures.append({"class": c.hazard_class, "object": c.obj, "placement": c.placement.key, "got": got[:k]})
    n = len(all_cases)
    return {"cases": n, "clutter": n_clutter, "top1": round(top1 / n, 4) if n else 0.0,
            f"top{k}": round(topk / n, 4) if n else 0.0, "failures": failures}
