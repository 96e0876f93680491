"""Hand-built, realistic scene graphs for detection tests (a few furniture pieces, clutter, hazards).

Numbers follow what the scene builder produces: heights from the knowledge base's support heights,
child reach ≤ 1.0 m, furniture and appliances standing on the floor.
"""

from __future__ import annotations

from anomalygen.schema import (
    BrainstormMode,
    Engine,
    GraphObject,
    HazardCategory,
    JointState,
    Provenance,
    Relation,
    Scenario,
    SceneGraph,
    TaskProposal,
)


def kb_props(category: str) -> list[str]:
    """The properties the scene builder would attach: the knowledge base's, none for unknown objects."""
    from anomalygen.knowledge import load_kb

    info = load_kb().objects.get(category)
    return list(info.properties) if info else []


def obj(name, category, props=None, *, pos=(0.5, 0.5, 0.0), size=(0.1, 0.1, 0.1), height=None, on_floor=None,
        edge=None, reach=None, joints=()):
    h = pos[2] - size[2] / 2 if height is None else height
    h = max(0.0, h)
    return GraphObject(
        name=name,
        category=category,
        properties=kb_props(category) if props is None else list(props),
        position=list(pos),
        size=list(size),
        height_above_floor=h,
        on_floor=(h < 0.01) if on_floor is None else on_floor,
        distance_to_edge=edge,
        child_reachable=(h <= 1.0) if reach is None else reach,
        joints=list(joints),
    )


def door(name, fraction, label="door"):
    return JointState(name=name, label=label, type="hinge", value=1.57 * fraction, range=(0.0, 1.57), closed_value=0.0)


def kitchen_furniture():
    """Counter along the wall, a dining table, a closed fridge and a closed cabinet."""
    return [
        obj("counter_0", "counter", None, pos=(0.5, 1.6, 0.45), size=(1.8, 0.6, 0.9)),
        obj("table_0", "Table", None, pos=(1.6, 0.5, 0.375), size=(1.0, 0.8, 0.75)),
        obj("refrigerator_0", "Refrigerator", None, pos=(-0.6, 1.6, 0.9), size=(0.7, 0.7, 1.8),
            joints=[door("refrigerator_0_door", 0.0)]),
        obj("storage_0", "StorageFurniture", None, pos=(2.6, 1.6, 0.45), size=(0.8, 0.5, 0.9),
            joints=[door("storage_0_door", 0.0)]),
    ]


def on_surface(name, category, props, surface_top, xy, *, edge=0.3, size=(0.1, 0.1, 0.05)):
    return obj(name, category, props, pos=(xy[0], xy[1], surface_top + size[2] / 2), size=size,
               height=surface_top, on_floor=False, edge=edge)


#: Unrelated everyday objects (no hazard property), placed on the table or counter away from edges.
CLUTTER = [
    ("book", 0.75, (1.4, 0.4)),
    ("cup", 0.9, (0.2, 1.6)),
    ("plate", 0.75, (1.8, 0.6)),
    ("tissue_box", 0.75, (1.6, 0.3)),
    ("basket", 0.9, (0.9, 1.6)),
    ("bowl", 0.9, (0.5, 1.5)),
    ("magazine", 0.75, (1.5, 0.7)),
]


def add_clutter(graph: SceneGraph, n: int) -> SceneGraph:
    """The same graph with ``n`` unrelated objects on the table/counter (as ``build --clutter`` adds)."""
    objs = list(graph.objects)
    rels = list(graph.relations)
    for i in range(n):
        cat, top, xy = CLUTTER[i % len(CLUTTER)]
        name = f"{cat}_c{i}"
        objs.append(on_surface(name, cat, None, top, xy, edge=0.2))
        rels.append(Relation(subject=name, predicate="on", object="table_0" if top < 0.8 else "counter_0"))
    return graph.model_copy(update={"objects": objs, "relations": rels})


def scene(scene_id, room, objects, relations=()):
    return SceneGraph(scene_id=scene_id, room=room, objects=list(objects), relations=list(relations))


def knife_on_counter_edge():
    """store_sharp_objects: a kitchen knife 4 cm from the counter's front edge."""
    objs = kitchen_furniture() + [
        on_surface("kitchen_knife_0", "kitchen_knife", None, 0.9, (0.6, 1.33), edge=0.04, size=(0.3, 0.04, 0.02)),
        on_surface("mug_0", "mug", None, 0.9, (0.1, 1.7), edge=0.2),
    ]
    rels = [Relation(subject="kitchen_knife_0", predicate="on", object="counter_0"),
            Relation(subject="mug_0", predicate="on", object="counter_0")]
    return scene("s-knife", "kitchen", objs, rels)


def pill_on_floor():
    """secure_medications: a pill bottle on the open floor of the living room."""
    objs = [
        obj("chair_0", "Chair", None, pos=(0.0, 2.0, 0.45), size=(0.5, 0.5, 0.9)),
        obj("coffee_table_0", "Table", None, pos=(0.0, 0.8, 0.2), size=(1.0, 0.6, 0.4)),
        obj("pill_bottle_0", "pill_bottle", None, pos=(1.5, -0.5, 0.04), size=(0.04, 0.04, 0.08)),
        on_surface("remote_0", "Remote", None, 0.4, (0.1, 0.8), edge=0.2),
    ]
    return scene("s-pill", "living_room", objs, [Relation(subject="pill_bottle_0", predicate="on_floor")])


def open_fridge():
    """close_open_refrigerator: the fridge door stands 80 % open."""
    objs = kitchen_furniture()
    objs[2] = objs[2].model_copy(update={"joints": [door("refrigerator_0_door", 0.8)]})
    objs.append(on_surface("apple_0", "apple", None, 0.75, (1.5, 0.5), edge=0.3))
    return scene("s-fridge", "kitchen", objs)


def two_hazards():
    """A knife at the counter edge and marbles on the floor in front of the table."""
    base = knife_on_counter_edge()
    objs = list(base.objects) + [
        obj("marble_0", "marble", None, pos=(1.0, -0.8, 0.008), size=(0.016, 0.016, 0.016)),
    ]
    return scene("s-two", "kitchen", objs, list(base.relations))


def make_task(task_id: str, hazard_class: str, category: str, hazard_object: str, target_asset: str, name: str,
              description: str, solution: str = "", room: str = "kitchen", placement: str = "counter_edge") -> TaskProposal:
    return TaskProposal(
        id=task_id,
        name=name,
        explanation="hidden from the detector",
        description=description,
        category=HazardCategory(category),
        hazard_class=hazard_class,
        target_asset=target_asset,
        scenario=Scenario(hazard_object=hazard_object, room=room, placement=placement),
        solution=solution,
        provenance=Provenance(engine=Engine.KNOWLEDGE, mode=BrainstormMode.BRAINSTORM),
    )


KNIFE_TASK = make_task(
    "t-knife", "store_sharp_objects", "household_hazard", "kitchen_knife", "Knife",
    "Put the chef's knife back in its drawer",
    "After slicing vegetables somebody left the chef's knife balanced at the front lip of the worktop, "
    "where a passing elbow could send it clattering down blade first.",
    "Pick the knife up and lay it inside the storage cabinet.",
)
PILL_TASK = make_task(
    "t-pill", "secure_medications", "child_safety", "pill_bottle", "Bottle",
    "Rescue grandma's tablets from the rug",
    "Grandma's heart tablets rolled off the sofa in their little bottle and now sit on the carpet "
    "where the twins crawl around after dinner.",
    "Carry the bottle to the medicine cabinet.", room="living_room", placement="floor",
)
FRIDGE_TASK = make_task(
    "t-fridge", "close_open_refrigerator", "hygiene", "Refrigerator", "Refrigerator",
    "Shut the fridge before the milk turns",
    "The children grabbed yoghurts and ran off, leaving the refrigerator gaping so cold air pours out "
    "and the groceries slowly warm.",
    "Swing the door closed.", placement="floor",
)
