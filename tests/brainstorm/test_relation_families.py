"""The reader's general mechanisms of issue 38: relation families, a place stated by its own
placement, compounds that name neither part, and people who are not objects.

Each test states one rule and checks it on several wordings, never one sentence's reading alone:
what lies on or in a filled sink or bath is near its water; "a pot on the stovetop" says the hob;
"knife block" is not a toy block; "Mum's mug" is a mug.
"""

from __future__ import annotations

import pytest

from anomalygen.brainstorm.free_text import TextGrounder
from anomalygen.brainstorm.line_compose import Refused
from anomalygen.knowledge import load_kb


@pytest.fixture(scope="module")
def reader():
    kb = load_kb()
    return TextGrounder(kb, catalogue=set(kb.objects))


def _read(reader, line):
    _, comp = reader.compose(line)
    return comp.hc.composition.mechanism, comp.fault.name


@pytest.mark.parametrize("line", [
    "A hair dryer is sitting on the edge of the bathroom basin, which is full of water.",
    "A hair dryer is plugged in right next to the bathroom basin, which is full of water.",
    "Someone left a hair dryer on the rim of the sink while it was full of water.",
    "There's a laptop charging on the edge of the bathtub.",
])
def test_on_the_rim_of_water_is_electricity_near_water(reader, line):
    mech, _ = _read(reader, line)
    assert mech == "electrical_near_water"


@pytest.mark.parametrize(("line", "fault"), [
    ("A kettle is plugged in right next to the kitchen sink.", "Kettle"),
    ("The toaster is standing beside the sink with water splashing onto it.", "Toaster"),
    ("A space heater is switched on right next to the bathtub.", "SpaceHeater"),
])
def test_a_portable_appliance_by_water_is_electricity_near_water(reader, line, fault):
    """A kettle, toaster or heater is an electrical device too; only heavy fixed appliances are not."""
    assert _read(reader, line) == ("electrical_near_water", fault)


def test_a_family_relation_gives_way_to_the_exact_one(reader):
    """'in the sink' is in the water (its own place), not only near it."""
    _, comp = reader.compose("A power strip is lying in the kitchen sink, which is full of water.")
    assert comp.hc.id == "take_electrical_out_of_water"


@pytest.mark.parametrize("line", [
    "There's a pot on the stovetop with its handle sticking out over the edge.",
    "A saucepan is on the front ring with the handle pointing out.",
    "A pan is on the cooker with its handle turned out.",
])
def test_a_place_is_stated_by_its_own_placement(reader, line):
    mech, fault = _read(reader, line)
    assert mech == "orientation" and fault in ("KitchenPot", "frying_pan")


def test_a_compound_of_two_names_is_neither(reader):
    """'knife block' (a holder of knives) names no toy block (the alias 'block'), and no knife is read
    into it; a cable named by what it serves is still a cable, and so is a possessive's."""
    with pytest.raises(Refused):
        reader.compose("The toddler has dragged a kitchen chair over to the counter where the knife block is.")
    for line in ("The iron's cord is stretched across the doorway.", "The toaster cable runs across the walkway."):
        p, comp = reader.compose(line)
        assert comp.fault.name == "power_cable", line


@pytest.mark.parametrize("line", [
    "A knife is on the kitchen counter behind the sofa.",
    "A hair dryer is in the cupboard under the sink.",
    "A toy car is at the bottom of the stairs.",
    "A knife is in the crib.",
])
def test_a_mention_nearby_is_not_a_place(reader, line):
    """A sofa mentioned as a landmark does not make the counter a low place; in or under a thing is
    not near it; the bottom of the stairs is not on them (a review found each built elsewhere)."""
    try:
        _, comp = reader.compose(line)
    except Refused:
        return
    place = comp.hc.composition.place
    assert place not in ("low", "near_water", "on_stairs", "near_crib"), (line, comp.hc.id)


@pytest.mark.parametrize("who", ["Mum's", "Grandad's", "My sister's", "The carer's"])
def test_a_person_is_not_the_object_at_fault(reader, who):
    mech, fault = _read(reader, f"{who} full mug of coffee is sitting at the edge of the table where the baby can grab it.")
    assert fault == "hot_mug"


@pytest.mark.parametrize("line", [
    "Dad's been smoking in bed again.",
    "The baby monitor cord hangs down into the crib.",
])
def test_what_cannot_be_built_is_refused(reader, line):
    with pytest.raises(Refused):
        reader.compose(line)


@pytest.mark.parametrize(("line", "kind"), [
    ("Rat poison is on the low shelf where the toddler can reach it.", "chemical_any"),
    ("Dishwasher tablets are on the floor where the baby crawls.", "detergent_pod"),
    ("The mouthwash has been left on the coffee table within the kids' reach.", "chemical_bottle"),
])
def test_poison_control_words_are_chemicals_under_the_users_word(reader, line, kind):
    _, comp = reader.compose(line)
    assert comp.hc.composition.mechanism == "within_child_reach"
    assert comp.fault.kind == kind and comp.fault.called
