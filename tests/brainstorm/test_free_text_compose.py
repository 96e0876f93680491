"""``--tasks-text`` offline: a line becomes the hazard it states, composed from the mechanisms, or is
refused with a reason that names the closest thing; it is never read as another object or danger."""

from __future__ import annotations

import pytest

from anomalygen.brainstorm.free_text import TextGrounder, tasks_from_lines
from anomalygen.brainstorm.line_compose import Refused
from anomalygen.knowledge import load_kb
from anomalygen.schema import Placement


@pytest.fixture(scope="module")
def reader():
    kb = load_kb()
    return TextGrounder(kb, catalogue=set(kb.objects))  # the knowledge's objects, assets or not


@pytest.mark.parametrize(("line", "cls", "hazard", "placement"), [
    ("A towel lies on the stove and the burner is lit.", "clear_burning_risk_off_heat_source", "towel", "on:Stove"),
    ("A power strip is lying in the bathroom sink, which is full of water.", "take_electrical_out_of_water", "PowerStrip",
     "inside:Sink"),
    ("The iron was left switched on, lying on the floor.", "switch_off_tool_on_floor", "iron", "floor"),
    ("The space heater stands right next to the curtains.", "switch_off_heater_near_fabric", "SpaceHeater", "near:Curtains"),
    ("Toys are lying all over the stairs.", "clear_item_from_stairs", "toy_block", "on:Stairs"),
    ("A pot on the stove has its handle turned outward.", "turn_pan_handle_inward", "KitchenPot", "on:Stove"),
    ("Paper towels are sitting right beside a lit burner.", "clear_burning_risk_near_heat_source", "PaperTowels", "near:Stove"),
    ("The baby gate at the top of the stairs was left open.", "close_baby_gate", "BabyGate", "floor"),
])
def test_a_line_becomes_the_hazard_it_states(reader, line, cls, hazard, placement):
    task = reader.proposal(line, 1)
    assert (task.hazard_class, task.scenario.hazard_object, task.scenario.placement.key) == (cls, hazard, placement)
    assert task.description == line and task.source == "user_text"
    by_field = {m.field: m for m in task.grounding}
    assert by_field["mechanism"].method == "composed" and by_field["scenario.hazard_object"].method == "parsed"
    assert by_field["hazard_class"].grounded == cls


def test_the_scene_is_told_the_states_and_parts_the_line_needs(reader):
    water = reader.proposal("A power strip is lying in the bathroom sink, which is full of water.", 1)
    assert water.scenario.states == {"Sink": ["contains_water"]} and "Sink" in water.scenario.co_objects
    fire = reader.proposal("A towel lies on the stove and the burner is lit.", 2)
    assert [(a.object, a.part, a.initial_state) for a in fire.articulations] == [("Stove", "knob", "on")]
    heater = reader.proposal("The space heater stands right next to the curtains.", 3)
    state = next(m for m in heater.grounding if m.field == "state")
    assert state.method == "class_default" and state.grounded == "switched_on"  # not said: recorded as assumed


@pytest.mark.parametrize(("line", "reason"), [
    ("Shards of a broken glass are scattered on the kitchen floor.", "broken"),
    ("A chainsaw was left running on the hallway floor.", "no object 'chainsaw'"),
    ("A bottle of cooking oil stands right on the hob.", "no object 'cooking oil'"),
    ("An extension cord runs under the living room rug.", "under rug"),
    ("A laptop is lying on the sofa.", "closest"),
])
def test_a_line_no_mechanism_covers_is_refused_with_a_reason(reader, line, reason):
    with pytest.raises(Refused, match=reason):
        reader.compose(line)


@pytest.mark.parametrize(("line", "said", "kind"), [
    ("A curling iron was left on by the bathroom sink.", "curling iron", "heated_hand_tool"),
    ("Somebody left the oven cleaner on the low coffee table.", "oven cleaner", None),
    ("The paracetamol is on the bedside table where the toddler can reach it.", "paracetamol", None),
])
def test_a_word_the_catalogue_lacks_is_built_as_its_kind_under_the_users_word(reader, line, said, kind):
    """The household lexicon: a proxy shape of the word's kind, named as the user named it everywhere
    the task speaks of it, and never under the proxy's own name."""
    from anomalygen.brainstorm.realise import nice
    from anomalygen.knowledge.lexicon import load_lexicon

    task = reader.proposal(line, 1)
    proxy = task.scenario.hazard_object
    assert task.scenario.called[proxy] == said
    reading = load_lexicon().read(said)
    assert reading is not None and reading.proxy == proxy and (kind is None or reading.kind == kind)
    assert set(load_kb().objects[proxy].properties) >= set(load_lexicon().kinds[reading.kind].properties)
    for text in (task.name, task.solution, task.success_condition, task.explanation):
        assert nice(proxy) not in text.lower() or nice(proxy) in said, (proxy, text)
    fault = next(m for m in task.grounding if m.field == "scenario.hazard_object")
    assert (fault.method, fault.written, fault.kind) == ("lexicon", said, reading.kind)


def test_one_bad_line_fails_alone_and_the_power_strip_in_a_full_sink_is_built_as_stated():
    lines = ["A chef's knife was left at the edge of the kitchen counter.",
             "Shards of a broken glass are scattered on the kitchen floor.",
             "A power strip is lying in the bathroom sink, which is full of water.",
             "Grandma's pill bottle was left on the low coffee table."]
    tasks, errors = tasks_from_lines(lines, load_kb())
    assert [t.scenario.hazard_object for t in tasks] == ["kitchen_knife", "PowerStrip", "pill_bottle"]
    assert set(errors) == {"line2"} and "broken" in errors["line2"]
    strip = tasks[1]
    assert (strip.scenario.placement, strip.scenario.room) == (Placement(relation="inside", other="Sink"), "bathroom")
    assert strip.scenario.states == {"Sink": ["contains_water"]}


@pytest.mark.parametrize(("line", "fault"), [
    ("A space heater is left on next to the sofa.", "SpaceHeater"),
    ("The medicine cabinet door is left open.", "medicine_cabinet"),
])
def test_a_class_about_its_target_gets_the_lines_object_as_target(reader, line, fault):
    """switch_off_appliance puts its 'on' on the target: with an oven as the target, a heater left on
    would be built as an oven left on."""
    task = reader.proposal(line, 1)
    assert (task.scenario.hazard_object, task.target_asset) == (fault, fault)
