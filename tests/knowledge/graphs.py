"""Small hand-built scene graphs for predicate and hazard-class tests (no simulator involved)."""

from __future__ import annotations

from anomalygen.knowledge import load_kb
from anomalygen.schema import GraphObject, JointState, Relation, SceneGraph

SURFACE = {"floor": 0.0, "low_table": 0.45, "table": 0.75, "counter": 0.9, "shelf": 1.4}


def joint(label: str, fraction: float, name: str | None = None) -> JointState:
    """A 0..1.5 rad hinge, closed at 0, opened to ``fraction`` of its range."""
    return JointState(name=name or f"{label}_joint", label=label, type="hinge", value=1.5 * fraction, range=(0.0, 1.5), closed_value=0.0)


def obj(
    name: str,
    category: str,
    *,
    at: str = "table",
    xy: tuple[float, float] = (0.0, 0.0),
    size: tuple[float, float, float] = (0.1, 0.1, 0.1),
    edge: float | None = 0.3,
    joints: list[JointState] | None = None,
    reachable: bool | None = None,
    props: list[str] | None = None,
) -> GraphObject:
    h = SURFACE[at]
    on_floor = at == "floor"
    return GraphObject(
        name=name,
        category=category,
        properties=props if props is not None else load_kb().properties_of(category),
        position=[xy[0], xy[1], h + size[2] / 2],
        size=list(size),
        height_above_floor=h,
        on_floor=on_floor,
        distance_to_edge=None if on_floor else edge,
        child_reachable=(h <= 1.0) if reachable is None else reachable,
        joints=joints or [],
    )


def furniture(name: str, category: str, xy=(2.0, 2.0), size=(0.8, 0.6, 0.9), joints=None, reachable=None) -> GraphObject:
    return obj(name, category, at="floor", xy=xy, size=size, joints=joints, reachable=reachable)


def graph(*objects: GraphObject, relations: list[Relation] | None = None, room: str = "kitchen") -> SceneGraph:
    rels = list(relations or [])
    for o in objects:
        if o.on_floor:
            rels.append(Relation(subject=o.name, predicate="on_floor"))
    return SceneGraph(scene_id="test", room=room, objects=list(objects), relations=rels)


def inside(a: str, b: str) -> Relation:
    return Relation(subject=a, predicate="inside", object=b)


def on(a: str, b: str) -> Relation:
    return Relation(subject=a, predicate="on", object=b)
