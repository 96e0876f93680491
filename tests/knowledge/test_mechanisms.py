"""Classes composed from mechanisms (data/knowledge/mechanisms.json): the hand-written classes are
reproduced by their compositions, every composed class fires on its own scene and ranks first there,
stays silent on the safe variant, and its success predicates judge the fix."""

from __future__ import annotations

import json

import pytest

from anomalygen.knowledge import HazardClass, load_kb
from anomalygen.knowledge.base import KNOWLEDGE_DIR
from anomalygen.knowledge.mechanisms import (
    MechanismSet,
    compose,
    composed_classes,
    load_mechanisms,
    same_calls,
)
from anomalygen.knowledge.predicates import evaluate, match_class
from anomalygen.schema import PredicateCall

from .graphs import furniture, graph, inside, joint, obj, on
from .test_predicates import top_class


def hand_written() -> dict[str, HazardClass]:
    raw = json.loads((KNOWLEDGE_DIR / "hazard_classes.json").read_text())["classes"]
    return {c["id"]: HazardClass.model_validate(c) for c in raw}


def stated(o, *states):
    return o.model_copy(update={"states": list(states)})


def test_every_hand_written_class_is_its_composition():
    """Same preconditions (any order), the same recipe and success, the same object at fault."""
    composed = {hc.id: hc for hc in composed_classes()}
    for cid, hand in hand_written().items():
        c = composed[cid]
        assert c.composition.legacy, cid
        assert same_calls(c.preconditions, hand.preconditions), cid
        assert (c.recipe, c.success, c.hazard_variable) == (hand.recipe, hand.success, hand.hazard_variable), cid


def test_loaded_classes_keep_the_hand_written_definitions_and_say_their_mechanism():
    kb, hand = load_kb(), hand_written()
    for cid, h in hand.items():
        loaded = kb.hazard_classes[cid]
        assert loaded.model_copy(update={"composition": None}) == h
        assert loaded.composition is not None and loaded.composition.mechanism
    new = [hc for hc in kb.hazard_classes.values() if not hc.composition.legacy]
    assert len(new) >= 20 and all(hc.id not in hand for hc in new)
    assert {hc.composition.mechanism for hc in new} >= {"ignition_near_combustible", "electrical_near_water", "orientation"}


def test_a_mechanism_added_as_data_becomes_a_class():
    """No code: a new composition row over existing fragments is a full HazardClass."""
    raw = json.loads((KNOWLEDGE_DIR / "mechanisms.json").read_text())
    raw.pop("_about")
    raw["mechanisms"].append({
        "id": "test_blocked_exit", "name": "Blocked exit", "category": "household_hazard", "danger": "a heavy thing on the stairs",
        "why": "It blocks the way out.", "at_risk": "everyone", "severity": 0.5,
        "compositions": [{"kind": "heavy", "place": "on_stairs", "fix": "take_down", "supports": ["Table"], "targets": ["Table"]}],
    })
    ms = MechanismSet.model_validate(raw)
    m = ms.mechanism("test_blocked_exit")
    hc = compose(ms, m, m.compositions[0], "heavy")
    assert hc.id == "heavy_on_stairs" and hc.composition.mechanism == "test_blocked_exit"
    assert PredicateCall(name="on", args={"object": "$hazard", "support": "Stairs"}) in hc.preconditions
    assert [s.action for s in hc.recipe] == ["take_off"] and hc.default_supports == ["Table"]
    g = graph(obj("dumbbell_0", "dumbbell", at="low_table"), furniture("stairs_0", "Stairs"), relations=[on("dumbbell_0", "stairs_0")])
    assert [m.bindings for m in match_class(hc, g)] == [{"$hazard": "dumbbell_0"}]


def crib(xy=(0.0, 0.0)):
    return furniture("crib_0", "Crib", xy=xy, size=(1.2, 0.7, 0.9))


def sink(*states, tap=0.0):
    return stated(furniture("sink_0", "Sink", xy=(0.0, 0.0), size=(0.6, 0.5, 0.9), joints=[joint("tap", tap)]), *states)


def stove(knob):
    return furniture("stove_0", "Stove", xy=(0.0, 0.0), size=(0.6, 0.6, 0.9), joints=[joint("knob", knob)])


def curtains():
    return furniture("curtains_0", "Curtains", xy=(0.0, 0.0), size=(2.0, 0.1, 2.2))


NEAR = (0.75, 0.0)  # 0.1 m beside a 1.2 m piece of furniture centred at the origin (objects are 0.1 m)

POSITIVE = {
    "hot_low_surface": lambda: graph(obj("mug_0", "hot_mug", at="low_table")),
    "sharp_near_crib": lambda: graph(obj("knife_0", "Knife", at="floor", xy=NEAR), crib(), room="nursery"),
    "choking_near_crib": lambda: graph(obj("coin_0", "coin", at="floor", xy=NEAR, size=(0.02, 0.02, 0.01)), crib()),
    "medication_near_crib": lambda: graph(obj("pill_0", "pill_bottle", at="floor", xy=NEAR), crib()),
    "cable_near_crib": lambda: graph(obj("cord_0", "power_cable", at="floor", xy=NEAR), crib()),
    "chemical_near_crib": lambda: graph(obj("pod_0", "detergent_pod", at="floor", xy=NEAR), crib()),
    "take_heavy_item_down": lambda: graph(obj("hammer_0", "hammer", at="shelf", reachable=False)),
    "clear_item_from_stairs": lambda: graph(
        obj("ball_0", "ball", at="low_table"), furniture("stairs_0", "Stairs"), relations=[on("ball_0", "stairs_0")]),
    "remove_chemical_from_fridge": lambda: graph(
        obj("bleach_0", "bleach_bottle", at="table", reachable=False),
        furniture("fridge_0", "Refrigerator", joints=[joint("door", 0.0)]), relations=[inside("bleach_0", "fridge_0")]),
    "separate_chemical_from_food": lambda: graph(
        obj("spray_0", "cleaning_spray", at="shelf", reachable=False), obj("bread_0", "bread_loaf", at="shelf", xy=(0.2, 0.0))),
    "close_open_door": lambda: graph(furniture("door_0", "Door", joints=[joint("door", 0.7)]), room="hallway"),
    "close_baby_gate": lambda: graph(furniture("gate_0", "BabyGate", joints=[joint("gate", 0.8)]), room="hallway"),
    "switch_off_tool_on_floor": lambda: graph(obj("iron_0", "iron", at="floor", joints=[joint("switch", 0.9)])),
    "switch_off_heat_tool": lambda: graph(obj("dryer_0", "hair_dryer", at="counter", joints=[joint("switch", 0.9)])),
    "turn_off_running_tap": lambda: graph(sink(tap=0.8), room="bathroom"),
    "remove_item_from_toaster": lambda: graph(
        obj("fork_0", "fork", at="counter"), furniture("toaster_0", "Toaster", joints=[joint("knob", 0.0)]),
        relations=[inside("fork_0", "toaster_0")]),
    "clear_burning_risk_off_heat_source": lambda: graph(
        obj("towel_0", "towel", at="counter"), stove(0.8), relations=[on("towel_0", "stove_0")]),
    "clear_burning_risk_near_heat_source": lambda: graph(
        obj("roll_0", "PaperTowels", at="counter", xy=(0.45, 0.0)), stove(0.8)),
    "switch_off_heater_near_fabric": lambda: graph(
        obj("heater_0", "SpaceHeater", at="floor", xy=(0.0, 0.2), size=(0.4, 0.2, 0.5), joints=[joint("knob", 0.8)]), curtains()),
    "move_candle_away_from_fabric": lambda: graph(stated(obj("candle_0", "candle", at="table", xy=(0.0, 0.2)), "lit"), curtains()),
    "take_electrical_out_of_water": lambda: graph(
        obj("strip_0", "PowerStrip", at="low_table"), sink("contains_water"), relations=[inside("strip_0", "sink_0")]),
    "move_electrical_away_from_water": lambda: graph(obj("dryer_0", "hair_dryer", at="counter", xy=(0.45, 0.0)), sink("contains_water")),
    "turn_pan_handle_inward": lambda: graph(stated(obj("pot_0", "KitchenPot", at="counter"), "handle_out")),
    "stand_iron_upright": lambda: graph(stated(obj("iron_0", "iron", at="table", joints=[joint("switch", 0.9)]), "face_down")),
    "clear_soft_things_from_crib": lambda: graph(
        obj("blanket_0", "Blanket", at="low_table"), crib(), relations=[inside("blanket_0", "crib_0")], room="nursery"),
}

NEGATIVE = {
    "clear_soft_things_from_crib": lambda: graph(obj("blanket_0", "Blanket", at="floor", xy=(3.0, 3.0)), crib(), room="nursery"),
    "hot_low_surface": lambda: graph(obj("mug_0", "hot_mug", at="table")),
    "sharp_near_crib": lambda: graph(obj("knife_0", "Knife", at="floor", xy=(3.0, 3.0)), crib()),
    "choking_near_crib": lambda: graph(obj("coin_0", "coin", at="floor", xy=(3.0, 3.0)), crib()),
    "medication_near_crib": lambda: graph(obj("pill_0", "pill_bottle", at="floor", xy=(3.0, 3.0)), crib()),
    "cable_near_crib": lambda: graph(obj("cord_0", "power_cable", at="floor", xy=(3.0, 3.0)), crib()),
    "chemical_near_crib": lambda: graph(obj("pod_0", "detergent_pod", at="floor", xy=(3.0, 3.0)), crib()),
    "take_heavy_item_down": lambda: graph(obj("hammer_0", "hammer", at="table")),
    "clear_item_from_stairs": lambda: graph(obj("ball_0", "ball", at="floor"), furniture("stairs_0", "Stairs")),
    "remove_chemical_from_fridge": lambda: graph(obj("bleach_0", "bleach_bottle", at="counter")),
    "separate_chemical_from_food": lambda: graph(
        obj("spray_0", "cleaning_spray", at="shelf", reachable=False), obj("bread_0", "bread_loaf", at="shelf", xy=(1.5, 0.0))),
    "close_open_door": lambda: graph(furniture("door_0", "Door", joints=[joint("door", 0.0)])),
    "close_baby_gate": lambda: graph(furniture("gate_0", "BabyGate", joints=[joint("gate", 0.0)])),
    "switch_off_tool_on_floor": lambda: graph(obj("iron_0", "iron", at="floor", joints=[joint("switch", 0.0)])),
    "switch_off_heat_tool": lambda: graph(obj("dryer_0", "hair_dryer", at="counter", joints=[joint("switch", 0.0)])),
    "turn_off_running_tap": lambda: graph(sink("contains_water", tap=0.0)),
    "remove_item_from_toaster": lambda: graph(
        obj("fork_0", "fork", at="counter"), furniture("toaster_0", "Toaster"), relations=[on("fork_0", "toaster_0")]),
    "clear_burning_risk_off_heat_source": lambda: graph(
        obj("towel_0", "towel", at="counter"), stove(0.0), relations=[on("towel_0", "stove_0")]),
    "clear_burning_risk_near_heat_source": lambda: graph(obj("roll_0", "PaperTowels", at="counter", xy=(0.45, 0.0)), stove(0.0)),
    "switch_off_heater_near_fabric": lambda: graph(
        obj("heater_0", "SpaceHeater", at="floor", xy=(0.0, 0.2), size=(0.4, 0.2, 0.5), joints=[joint("knob", 0.0)]), curtains()),
    "move_candle_away_from_fabric": lambda: graph(obj("candle_0", "candle", at="table", xy=(0.0, 0.2)), curtains()),
    "take_electrical_out_of_water": lambda: graph(obj("strip_0", "PowerStrip", at="low_table"), sink(), relations=[inside("strip_0", "sink_0")]),
    "move_electrical_away_from_water": lambda: graph(obj("dryer_0", "hair_dryer", at="counter", xy=(0.45, 0.0)), sink()),
    "turn_pan_handle_inward": lambda: graph(obj("pot_0", "KitchenPot", at="counter")),
    # an iron rests on its soleplate whenever it is put down: only a hot (switched on) one is a hazard
    "stand_iron_upright": lambda: graph(stated(obj("iron_0", "iron", at="table", joints=[joint("switch", 0.0)]), "face_down")),
}


def test_every_composed_class_has_a_positive_and_negative_scene():
    composed = {cid for cid, hc in load_kb().hazard_classes.items() if not hc.composition.legacy}
    assert set(POSITIVE) == composed == set(NEGATIVE)


@pytest.mark.parametrize("class_id", sorted(POSITIVE))
def test_composed_class_fires_and_ranks_first_on_its_scene(class_id):
    g = POSITIVE[class_id]()
    assert match_class(load_kb().hazard_classes[class_id], g), f"{class_id} did not match its own scene"
    # a hot iron face down is a heat tool left on too; switching it off (a fix the robot has) ends both
    assert top_class(g) == {"stand_iron_upright": "switch_off_heat_tool"}.get(class_id, class_id)


@pytest.mark.parametrize("class_id", sorted(NEGATIVE))
def test_composed_class_is_silent_on_the_safe_variant(class_id):
    assert match_class(load_kb().hazard_classes[class_id], NEGATIVE[class_id]()) == []


def test_composed_success_predicates_judge_the_fix():
    kb = load_kb()
    counter = furniture("counter_0", "counter", xy=(2.0, 0.0), size=(1.5, 0.6, 0.9))
    cases = {
        "clear_burning_risk_off_heat_source": (
            {"$hazard": "towel_0", "$source": "stove_0", "$support": "counter_0"},
            POSITIVE["clear_burning_risk_off_heat_source"](),
            graph(obj("towel_0", "towel", at="counter", xy=(2.0, 0.0)), stove(0.0), counter, relations=[on("towel_0", "counter_0")])),
        "take_electrical_out_of_water": (
            {"$hazard": "strip_0", "$water": "sink_0", "$support": "counter_0"},
            POSITIVE["take_electrical_out_of_water"](),
            graph(obj("strip_0", "PowerStrip", at="counter", xy=(2.0, 0.0)), sink("contains_water"), counter,
                  relations=[on("strip_0", "counter_0")])),
        "switch_off_tool_on_floor": (
            {"$hazard": "iron_0", "$support": "counter_0"},
            POSITIVE["switch_off_tool_on_floor"](),
            graph(obj("iron_0", "iron", at="counter", xy=(2.0, 0.0), joints=[joint("switch", 0.0)]), counter,
                  relations=[on("iron_0", "counter_0")])),
        "take_heavy_item_down": (
            {"$hazard": "hammer_0", "$support": "counter_0"},
            POSITIVE["take_heavy_item_down"](),
            graph(obj("hammer_0", "hammer", at="counter", xy=(2.0, 0.0)), counter, relations=[on("hammer_0", "counter_0")])),
    }
    for cid, (b, before, after) in cases.items():
        hc = kb.hazard_classes[cid]
        assert not all(evaluate(c, before, b).holds for c in hc.success), cid
        assert all(evaluate(c, after, b).holds for c in hc.success), cid
        assert match_class(hc, after) == [], cid


def test_is_on_and_has_state_read_controls_and_states():
    call = lambda name, **args: PredicateCall(name=name, args=args)  # noqa: E731
    g = graph(stove(0.8), stated(obj("candle_0", "candle", xy=(3, 3)), "lit"), obj("mug_0", "mug", xy=(4, 4)),
              stated(furniture("sink_0", "Sink", xy=(-3, -3), joints=[joint("tap", 0.0)]), "contains_water"))
    assert evaluate(call("is_on", object="stove_0"), g).holds
    assert evaluate(call("is_on", object="candle_0"), g).holds  # no control: lit says on
    assert not evaluate(call("is_on", object="mug_0"), g).holds
    assert not evaluate(call("is_on", object="sink_0"), g).holds  # its tap is shut, water or not
    assert evaluate(call("has_state", object="sink_0", state="wet|contains_water"), g).holds
    assert not evaluate(call("has_state", object="mug_0", state="contains_water"), g).holds


def test_new_objects_have_knowledge_with_the_agreed_names():
    kb = load_kb()
    for name in ("Stove", "Sink", "Bathtub", "SpaceHeater", "PowerStrip", "Curtains", "Crib", "Stairs", "Bookcase",
                 "BabyGate", "PaperTowels", "Blanket", "towel", "rug", "candle", "iron", "hair_dryer"):
        assert name in kb.objects, name
    assert kb.objects["Stove"].part("knob") and kb.objects["BabyGate"].part("gate") and kb.objects["Sink"].part("tap")
    assert {"heat_source"} <= set(kb.objects["Stove"].properties) and "water_source" in kb.objects["Bathtub"].properties
    assert "combustible" in kb.objects["Curtains"].properties and "combustible" not in kb.objects["Lighter"].properties
    ms = load_mechanisms()
    assert set(ms.places["in_water"].states) == {"$water"}


def test_a_chemical_shut_in_a_latched_safe_beside_the_crib_is_no_hazard():
    """Near the crib means within the baby's reach: a pod locked in a safe that stands 0.2 m from the
    crib is out of it (the seed-19 demo's referee called such a fix unresolved)."""
    hc = load_kb().hazard_classes["chemical_near_crib"]
    assert match_class(hc, POSITIVE["chemical_near_crib"]())
    locked = graph(obj("pod_0", "detergent_pod", at="floor", xy=NEAR, reachable=False), crib())
    assert not match_class(hc, locked)


def test_a_composition_says_why_its_own_combination_is_dangerous():
    """A mechanism's text may speak of several cases (a pan handle and an iron); a composition that
    needs its own reason states it, and the others keep the mechanism's."""
    kb = load_kb()
    pan, iron = kb.hazard_classes["turn_pan_handle_inward"], kb.hazard_classes["stand_iron_upright"]
    assert "iron" not in pan.why and "pan" in pan.why
    assert "pan" not in iron.why and "iron" in iron.why
    assert "microwave" not in kb.hazard_classes["remove_item_from_toaster"].why
    assert "suffocat" in kb.hazard_classes["clear_soft_things_from_crib"].why
    ms = load_mechanisms()
    left_on = ms.mechanism("left_on")
    heat_tool = next(c for c in left_on.compositions if c.id == "switch_off_heat_tool")
    # the mechanism's reason speaks of taps too ("floods"); a heating tool states its own
    assert heat_tool.why and "flood" in left_on.why and "flood" not in kb.hazard_classes["switch_off_heat_tool"].why


def _bleach_by_banana(*, door: float, banana_inside: bool = False):
    """A bleach bottle in a safe standing on the floor, a banana 5 cm from the safe's side (t0044's end)."""
    rels = [inside("bleach_0", "safe_0")] + ([inside("banana_0", "safe_0")] if banana_inside else [])
    return graph(
        obj("bleach_0", "bleach_bottle", at="floor", xy=(0.0, 0.0), reachable=False),
        obj("banana_0", "banana", at="floor", xy=(0.0, 0.25)),
        furniture("safe_0", "Safe", xy=(0.0, 0.0), size=(0.4, 0.4, 0.3), joints=[joint("door", door)]),
        relations=rels,
    )


def test_chemical_shut_in_a_container_is_not_among_the_food_outside_it():
    """t0044 at d48b921: the bleach was locked in the safe, yet "chemical near food" still fired
    because a banana lay on the floor beside the safe. Shut walls keep the two apart; an open door
    does not, and food shut in with the chemical is still among it."""
    cls = load_kb().hazard_classes["separate_chemical_from_food"]
    assert match_class(cls, _bleach_by_banana(door=0.0)) == []
    assert match_class(cls, _bleach_by_banana(door=0.5)), "an open door leaves the bleach by the banana"
    assert match_class(cls, _bleach_by_banana(door=0.0, banana_inside=True)), "shut in together is still among food"


def test_walls_separate_takes_true_or_false_and_refuses_anything_else():
    """A class (from the knowledge base or an LLM) that writes walls_separate='yes' is refused with a
    reason, not read as 'false'."""
    from anomalygen.knowledge.predicates import PredicateError

    g = _bleach_by_banana(door=0.0)
    args = {"a": "bleach_0", "b": "banana_0", "max_distance": 0.2}
    assert evaluate(PredicateCall(name="near", args={**args, "walls_separate": "false"}), g).holds
    assert not evaluate(PredicateCall(name="near", args={**args, "walls_separate": "true"}), g).holds
    with pytest.raises(PredicateError, match="must be 'true' or 'false'"):
        evaluate(PredicateCall(name="near", args={**args, "walls_separate": "yes"}), g)
    kb = load_kb()
    hc = kb.hazard_classes["separate_chemical_from_food"]
    bad = [c.model_copy(update={"args": {**c.args, "walls_separate": "yes"}}) if c.name == "near" else c
           for c in hc.preconditions]
    assert any("walls_separate must be 'true' or 'false'" in p
               for p in kb.class_problems(hc.model_copy(update={"preconditions": bad})))
    assert kb.class_problems(hc) == []
