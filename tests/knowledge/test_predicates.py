"""Predicates and hazard classes on hand-built scene graphs: each class fires on its own scene, ranks
first there, stays silent on a near-miss, and its success predicates hold after the fix."""

from __future__ import annotations

import pytest

from anomalygen.knowledge import load_kb
from anomalygen.knowledge.predicates import PREDICATES, PredicateError, evaluate, match_class
from anomalygen.schema import PredicateCall, Relation

from .graphs import furniture, graph, inside, joint, obj, on


def top_class(g) -> str | None:
    kb = load_kb()
    hits = [(hc.severity, hc.id) for hc in kb.hazard_classes.values() if match_class(hc, g)]
    return max(hits)[1] if hits else None


def counter():
    return furniture("counter_0", "counter", xy=(0.0, 0.0), size=(1.5, 0.6, 0.9))


POSITIVE = {
    "store_sharp_objects": lambda: graph(obj("knife_0", "Knife", at="counter"), counter()),
    "reduce_tripping_hazards": lambda: graph(obj("shoe_0", "shoe", at="floor"), furniture("table_0", "Table")),
    "manage_chemical_risks": lambda: graph(obj("bleach_0", "bleach_bottle", at="counter"), counter()),
    "dispose_spoiled_food": lambda: graph(obj("bread_0", "moldy_bread", at="table"), furniture("table_0", "Table")),
    "close_open_refrigerator": lambda: graph(furniture("fridge_0", "Refrigerator", joints=[joint("door", 0.8)])),
    "pick_up_floor_litter": lambda: graph(obj("wrapper_0", "wrapper", at="floor", xy=(1.9, 1.3)), furniture("table_0", "Table")),
    "ventilate_room": lambda: graph(
        furniture("window_0", "Window", joints=[joint("window", 0.0)]), obj("candle_0", "candle", at="table", xy=(0.0, 0.0))
    ),
    "keep_sharp_away_from_children": lambda: graph(obj("scissors_0", "Scissors", at="floor")),
    "remove_choking_hazards": lambda: graph(obj("marble_0", "marble", at="floor", size=(0.02, 0.02, 0.02))),
    "close_open_furniture": lambda: graph(furniture("cab_0", "StorageFurniture", joints=[joint("door", 0.6), joint("drawer", 0.0)])),
    "secure_medications": lambda: graph(obj("pill_0", "pill", at="low_table", size=(0.01, 0.01, 0.005))),
    "store_perishable_food": lambda: graph(
        obj("meat_0", "raw_meat_tray", at="counter"), furniture("fridge_0", "Refrigerator", joints=[joint("door", 0.0)])
    ),
    "switch_off_appliance": lambda: graph(furniture("oven_0", "Oven", joints=[joint("door", 0.0), joint("knob", 1.0)])),
    "clear_cable_from_walkway": lambda: graph(obj("cable_0", "power_cable", at="floor", size=(1.2, 0.02, 0.01))),
    "keep_chemicals_from_children": lambda: graph(obj("pod_0", "detergent_pod", at="floor", size=(0.04, 0.04, 0.02))),
    "move_hot_item_from_edge": lambda: graph(obj("mug_0", "hot_mug", at="table", edge=0.03)),
    "close_window_near_child": lambda: graph(furniture("window_0", "Window", joints=[joint("window", 0.6)])),
    "close_oven_or_microwave": lambda: graph(furniture("oven_0", "Oven", joints=[joint("door", 0.7), joint("knob", 0.0)])),
    "move_fragile_from_edge": lambda: graph(obj("vase_0", "vase", at="table", edge=0.05)),
    "move_heavy_from_edge": lambda: graph(obj("hammer_0", "hammer", at="table", edge=0.05)),
    "keep_fire_starters_from_children": lambda: graph(obj("lighter_0", "Lighter", at="table")),
    "close_toilet_lid": lambda: graph(furniture("toilet_0", "Toilet", joints=[joint("lid", 0.9)]), room="bathroom"),
    "push_heavy_item_out_of_walkway": lambda: graph(obj("dumbbell_0", "dumbbell", at="floor"), furniture("table_0", "Table")),
    "close_open_portable_container": lambda: graph(furniture("box_0", "Box", size=(0.4, 0.3, 0.3), joints=[joint("lid", 0.8)])),
    "remove_item_from_appliance": lambda: graph(
        obj("fork_0", "fork", at="counter"), furniture("mw_0", "Microwave", joints=[joint("door", 0.0)]), counter(),
        relations=[inside("fork_0", "mw_0")]),
    "pick_item_off_floor_onto_desk": lambda: graph(obj("phone_0", "Phone", at="floor"), furniture("table_0", "Table")),
}

NEGATIVE = {
    "store_sharp_objects": lambda: graph(obj("knife_0", "Knife", at="counter"), counter(), relations=[inside("knife_0", "counter_0")]),
    "reduce_tripping_hazards": lambda: graph(obj("shoe_0", "shoe", at="floor", xy=(1.5, 2.0)), furniture("table_0", "Table")),
    "manage_chemical_risks": lambda: graph(obj("bleach_0", "bleach_bottle", at="shelf", reachable=False)),
    "dispose_spoiled_food": lambda: graph(obj("apple_0", "apple", at="table")),
    "close_open_refrigerator": lambda: graph(furniture("fridge_0", "Refrigerator", joints=[joint("door", 0.02)])),
    "pick_up_floor_litter": lambda: graph(obj("wrapper_0", "wrapper", at="table")),
    "ventilate_room": lambda: graph(furniture("window_0", "Window", joints=[joint("window", 0.0)]), obj("book_0", "book")),
    "keep_sharp_away_from_children": lambda: graph(obj("scissors_0", "Scissors", at="shelf", reachable=False)),
    "remove_choking_hazards": lambda: graph(obj("marble_0", "marble", at="shelf", reachable=False)),
    "close_open_furniture": lambda: graph(furniture("cab_0", "StorageFurniture", joints=[joint("door", 0.0), joint("drawer", 0.03)])),
    "secure_medications": lambda: graph(
        obj("pill_0", "pill", at="shelf", reachable=False), furniture("cab_0", "medicine_cabinet"), relations=[inside("pill_0", "cab_0")]
    ),
    "store_perishable_food": lambda: graph(
        obj("meat_0", "raw_meat_tray", at="shelf", reachable=False),
        furniture("fridge_0", "Refrigerator", joints=[joint("door", 0.0)]),
        relations=[inside("meat_0", "fridge_0")],
    ),
    "switch_off_appliance": lambda: graph(furniture("oven_0", "Oven", joints=[joint("door", 0.0), joint("knob", 0.0)])),
    "clear_cable_from_walkway": lambda: graph(obj("cable_0", "power_cable", at="table")),
    "keep_chemicals_from_children": lambda: graph(obj("pod_0", "detergent_pod", at="shelf", reachable=False)),
    "move_hot_item_from_edge": lambda: graph(obj("mug_0", "hot_mug", at="table", edge=0.3)),
    "close_window_near_child": lambda: graph(furniture("window_0", "Window", joints=[joint("window", 0.6)], reachable=False)),
    "close_oven_or_microwave": lambda: graph(furniture("oven_0", "Oven", joints=[joint("door", 0.0), joint("knob", 0.0)])),
    "move_fragile_from_edge": lambda: graph(obj("vase_0", "vase", at="table", edge=0.4)),
    "move_heavy_from_edge": lambda: graph(obj("hammer_0", "hammer", at="table", edge=0.4)),
    "keep_fire_starters_from_children": lambda: graph(obj("lighter_0", "Lighter", at="shelf", reachable=False)),
    "close_toilet_lid": lambda: graph(furniture("toilet_0", "Toilet", joints=[joint("lid", 0.0)]), room="bathroom"),
    "push_heavy_item_out_of_walkway": lambda: graph(obj("dumbbell_0", "dumbbell", at="floor", xy=(1.5, 2.0)), furniture("table_0", "Table")),
    "close_open_portable_container": lambda: graph(furniture("box_0", "Box", size=(0.4, 0.3, 0.3), joints=[joint("lid", 0.02)])),
    "remove_item_from_appliance": lambda: graph(
        obj("fork_0", "fork", at="counter"), furniture("mw_0", "Microwave", joints=[joint("door", 0.0)]), counter(),
        relations=[on("fork_0", "counter_0")]),
    "pick_item_off_floor_onto_desk": lambda: graph(obj("phone_0", "Phone", at="table")),
}


def test_every_class_has_a_positive_and_negative_scene():
    """Every hand-written class here; the classes composed from mechanisms in test_mechanisms.py."""
    hand_written = {cid for cid, hc in load_kb().hazard_classes.items() if hc.composition is None or hc.composition.legacy}
    assert set(POSITIVE) == hand_written == set(NEGATIVE)


@pytest.mark.parametrize("class_id", sorted(POSITIVE))
def test_class_fires_and_ranks_first_on_its_scene(class_id):
    g = POSITIVE[class_id]()
    matches = match_class(load_kb().hazard_classes[class_id], g)
    assert matches, f"{class_id} did not match its own scene"
    assert matches[0].explanation and matches[0].score == load_kb().hazard_classes[class_id].severity
    assert top_class(g) == class_id


@pytest.mark.parametrize("class_id", sorted(NEGATIVE))
def test_class_is_silent_on_near_miss(class_id):
    assert match_class(load_kb().hazard_classes[class_id], NEGATIVE[class_id]()) == []


def test_binding_names_the_right_object_among_clutter():
    g = graph(obj("book_0", "book", xy=(0.5, 0.0)), obj("knife_0", "Knife", at="counter"), counter(), obj("cup_0", "cup"))
    matches = match_class(load_kb().hazard_classes["store_sharp_objects"], g)
    assert [m.bindings for m in matches] == [{"$hazard": "knife_0"}]


def test_success_predicates_hold_after_the_fix():
    kb = load_kb()
    hc = kb.hazard_classes["secure_medications"]
    before = graph(obj("pill_0", "pill", at="table"), furniture("cab_0", "medicine_cabinet"))
    after = graph(
        obj("pill_0", "pill", at="shelf", reachable=False), furniture("cab_0", "medicine_cabinet"), relations=[inside("pill_0", "cab_0:inner")]
    )
    b = {"$hazard": "pill_0", "$container": "cab_0"}
    assert not all(evaluate(c, before, b).holds for c in hc.success)
    assert all(evaluate(c, after, b).holds for c in hc.success)
    assert match_class(hc, after) == []

    fridge = kb.hazard_classes["close_open_refrigerator"]
    closed = graph(furniture("fridge_0", "Refrigerator", joints=[joint("door", 0.0)]))
    assert all(evaluate(c, closed, {"$target": "fridge_0"}).holds for c in fridge.success)

    hot = kb.hazard_classes["move_hot_item_from_edge"]
    moved = graph(obj("mug_0", "hot_mug", at="table", edge=0.25))
    fell = graph(obj("mug_0", "hot_mug", at="floor"))
    assert all(evaluate(c, moved, {"$hazard": "mug_0"}).holds for c in hot.success)
    assert not all(evaluate(c, fell, {"$hazard": "mug_0"}).holds for c in hot.success)

    cable = kb.hazard_classes["clear_cable_from_walkway"]
    laid = graph(obj("cable_0", "power_cable", at="table"), furniture("table_0", "Table"), relations=[on("cable_0", "table_0")])
    assert all(evaluate(c, laid, {"$hazard": "cable_0", "$support": "table_0"}).holds for c in cable.success)


def test_new_classes_success_predicates_judge_the_fix():
    """The four classes of the push/lid/take-out/place-on actions: their success holds on the fixed
    scene, not on the hazardous one, and the class no longer fires after the fix."""
    kb = load_kb()
    table = furniture("table_0", "Table")
    cases = {
        "push_heavy_item_out_of_walkway": (
            {"$hazard": "dumbbell_0", "$support": "table_0"},
            graph(obj("dumbbell_0", "dumbbell", at="floor"), table),
            graph(obj("dumbbell_0", "dumbbell", at="floor", xy=(1.5, 2.0)), table)),
        "close_open_portable_container": (
            {"$target": "box_0"}, PUSHED_OPEN(), graph(furniture("box_0", "Box", joints=[joint("lid", 0.0)]))),
        "remove_item_from_appliance": (
            {"$hazard": "fork_0", "$target": "mw_0", "$support": "counter_0"},
            POSITIVE["remove_item_from_appliance"](),
            graph(obj("fork_0", "fork", at="counter"), furniture("mw_0", "Microwave", joints=[joint("door", 0.0)]), counter(),
                  relations=[on("fork_0", "counter_0")])),
        "pick_item_off_floor_onto_desk": (
            {"$hazard": "phone_0", "$support": "table_0"},
            graph(obj("phone_0", "Phone", at="floor"), table),
            graph(obj("phone_0", "Phone", at="table"), table, relations=[on("phone_0", "table_0")])),
    }
    for cid, (b, before, after) in cases.items():
        hc = kb.hazard_classes[cid]
        assert not all(evaluate(c, before, b).holds for c in hc.success), cid
        assert all(evaluate(c, after, b).holds for c in hc.success), cid
        assert match_class(hc, after) == [], cid


def PUSHED_OPEN():  # noqa: N802 - a scene factory like POSITIVE's
    return graph(furniture("box_0", "Box", joints=[joint("lid", 0.8)]))


def test_predicate_details():
    g = graph(
        obj("a", "cup", at="floor", xy=(0, 0)),
        obj("b", "cup", at="floor", xy=(0.25, 0)),
        furniture("t", "Table", xy=(3, 3), joints=[joint("drawer", 0.5)]),
        relations=[Relation(subject="a", predicate="under", object="t")],
    )
    call = lambda name, **args: PredicateCall(name=name, args=args)  # noqa: E731
    assert evaluate(call("near", a="a", b="b", max_distance=0.2), g).holds  # 0.15 m gap
    assert not evaluate(call("near", a="a", b="b", max_distance=0.1), g).holds
    assert not evaluate(call("in_walkway", object="a"), g).holds  # under the table
    assert evaluate(call("in_walkway", object="b"), g).holds
    assert evaluate(call("joint_open", object="t", label="drawer", min_fraction=0.5), g).holds
    assert not evaluate(call("joint_closed", object="t", label="*", max_fraction=0.1), g).holds
    assert not evaluate(call("joint_open", object="t", label="door", min_fraction=0.1), g).holds  # no door
    assert evaluate(call("height_above_floor", object="t", max=0.0), g).holds
    assert evaluate(call("room_is", room="bathroom|kitchen"), g).holds
    assert evaluate(PredicateCall(name="on_floor", args={"object": "$x"}, negate=True), g, {"$x": "t"}).holds is False
    assert evaluate(call("category_is", object="t", category="Chair|Table"), g).holds
    with pytest.raises(PredicateError, match="not bound"):
        evaluate(call("on_floor", object="$hazard"), g, {})
    with pytest.raises(PredicateError, match="unknown predicate"):
        evaluate(call("levitating", object="a"), g)
    assert set(PREDICATES) >= {
        "has_property", "on_floor", "height_above_floor", "near_edge", "child_reachable", "inside", "on",
        "joint_open", "joint_closed", "near", "in_walkway", "category_is",
    }
