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
    Relation,
    SceneGraph,
    part_labels,
)

#: Top-surface heights (m) per placement, inside the knowledge base's SUPPORT_HEIGHTS ranges.
SURFACE_TOP = {"table": 0.75, "table_edge": 0.75, "counter": 0.9, "counter_edge": 0.9, "shelf": 1.4, "low_table": 0.42}
EDGE_GAP = 0.04  # distance to the edge for *_edge placements (m)


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
    """``n`` benign objects (no hazard property) resting on the table and counter, away from edges."""
    names = sorted(kb.benign_objects())
    objs, rels = [], []
    spots = [(1.4, 0.35, 0.75, "table_0"), (1.8, 0.65, 0.75, "table_0"), (0.1, 1.6, 0.9, "counter_0"),
             (0.9, 1.65, 0.9, "counter_0"), (1.5, 0.7, 0.75, "table_0"), (0.5, 1.55, 0.9, "counter_0")]
    for i in range(n):
        cat = names[(7 * i) % len(names)]
        x, y, top, support = spots[i % len(spots)]
        name = f"{cat.lower()}_c{i}"
        objs.append(_obj(name, cat, _props(kb, cat), pos=(x, y, top + 0.05), size=(0.1, 0.1, 0.1), height=top,
                         on_floor=False, edge=0.2))
        rels.append(Relation(subject=name, predicate="on", object=support))
    return objs, rels


@dataclass(frozen=True)
class Case:
    hazard_class: str
    obj: str
    placement: str
    graph: SceneGraph
    instance: str


def _hazard_objects(kb, hc, obj: str, placement: str) -> tuple[list[GraphObject], list[Relation], str]:
    name = f"{obj.lower()}_0"
    props = _props(kb, obj)
    if hc.hazard_variable == "$target" and hc.articulation is not None:
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
    if placement in ("floor", "walkway"):
        return [_obj(name, obj, props, pos=(1.0, -0.8, 0.03), size=(0.1, 0.1, 0.06), height=0.0, on_floor=True)], [], name
    if placement.startswith("inside:"):
        parent = placement.split(":", 1)[1]
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
    top = SURFACE_TOP.get(placement.split(":", 1)[-1], 0.75)
    edge = EDGE_GAP if placement.endswith("_edge") else 0.3
    o = _obj(name, obj, props, pos=(1.6, 0.5, top + 0.03), size=(0.1, 0.1, 0.06), height=top, on_floor=False, edge=edge,
             reach=top <= CHILD_REACH)
    support = "counter_0" if "counter" in placement else "table_0"
    return [o], [Relation(subject=name, predicate="on", object=support)], name


def cases(kb, *, n_clutter: int = 0) -> list[Case]:
    out = []
    extra, extra_rels = clutter(kb, n_clutter)
    for hc in sorted(kb.hazard_classes.values(), key=lambda h: h.id):
        for obj in kb.hazard_candidates(hc):
            for placement in kb.placements_for(hc, obj):
                objs, rels, inst = _hazard_objects(kb, hc, obj, placement)
                graph = SceneGraph(scene_id=f"{hc.id}-{obj}-{placement}", room="kitchen",
                                   objects=furniture(kb) + objs + extra, relations=rels + extra_rels)
                out.append(Case(hc.id, obj, placement, graph, inst))
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
        want = (c.instance, c.hazard_class)
        top1 += bool(got) and got[0] == want
        topk += want in got
        if not got or got[0] != want:
            failures.append({"class": c.hazard_class, "object": c.obj, "placement": c.placement, "got": got[:k]})
    n = len(all_cases)
    return {"cases": n, "clutter": n_clutter, "top1": round(top1 / n, 4) if n else 0.0,
            f"top{k}": round(topk / n, 4) if n else 0.0, "failures": failures}
