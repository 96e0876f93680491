"""Brainstorming draws only what can be built: a thing goes inside a holder only if it fits there."""

from __future__ import annotations

import numpy as np

from anomalygen.brainstorm.drawable import fits_inside, placements_for, why_not_drawable
from anomalygen.knowledge import load_kb
from anomalygen.scene import asset_choice
from anomalygen.schema import Placement


def test_an_object_longer_than_every_interior_is_never_placed_inside():
    """A spoon (at least 0.15 m) never fits a toaster's slot (under 2 cm across), nor a 0.8 m power
    cable a sink's basin: every such task failed its build, "does not fit a 0.01 m space"."""
    kb = load_kb()
    assert not fits_inside(kb, "spoon", "Toaster") and not fits_inside(kb, "fork", "Toaster")
    assert fits_inside(kb, "fork", "Microwave")
    water = kb.hazard_classes["take_electrical_out_of_water"]
    assert Placement(relation="inside", other="Sink") not in placements_for(kb, water, "power_cable")
    assert Placement(relation="inside", other="Bathtub") in placements_for(kb, water, "power_cable")
    assert Placement(relation="inside", other="Sink") in placements_for(kb, water, "PowerStrip")
    # a class whose only object never fits its only holder is not drawn at all, and says why
    toaster = kb.hazard_classes["remove_item_from_toaster"]
    assert "room inside" in why_not_drawable(kb, toaster)
    # the rule is the builder's own cap on what goes inside
    for seed in range(3):
        from anomalygen.assets.core import generate

        biggest = generate("Toaster", seed, size=asset_choice.size_bounds(kb, "Toaster")[1])
        assert asset_choice.cavity_cap(biggest) < asset_choice.size_bounds(kb, "spoon")[0]


def test_a_hazard_the_fix_puts_away_is_drawn_only_with_a_container_it_fits():
    """The crib's cables are put away in a safe (it latches); a cable lies straight, 0.5 m and more,
    and the roomiest safe holds 0.46 m: two extension cords of the loop at bf44e13 failed their
    builds, "does not fit a 0.31 m space: the task names the Safe". The power strip fits."""
    from anomalygen.brainstorm.drawable import containers_for, hazards_for

    kb = load_kb()
    crib = kb.hazard_classes["cable_near_crib"]
    assert containers_for(kb, crib, "PowerStrip") == ["Safe"]
    assert containers_for(kb, crib, "extension_cord") == []
    assert hazards_for(kb, crib) == ["PowerStrip"]
    # the sampler names only a container that fits
    litter = kb.hazard_classes["pick_up_floor_litter"]
    for hazard in hazards_for(kb, litter):
        least = asset_choice.size_bounds(kb, hazard)[0]
        assert containers_for(kb, litter, hazard), hazard
        for c in containers_for(kb, litter, hazard):
            from anomalygen.brainstorm.drawable import _roomiest

            assert _roomiest(kb, c, asset_choice.container_room) >= least


def test_the_food_a_chemical_stands_among_is_not_a_second_hazard():
    """t0044 of the seed-0 loop at 8b4be29: the bleach was drawn beside a box of leftovers. Leftovers
    left out are a hazard of their own (store_perishable_food), and the kitchen had no fridge, so
    no robot could resolve the task. The object beside the hazard is now one that is harmless left
    out, whenever there is such an object."""
    import numpy as np

    from anomalygen.brainstorm.drawable import harmless_first
    from anomalygen.brainstorm.idea_sampler import IdeaSampler

    kb = load_kb()
    assert harmless_first(kb, ["leftover_container", "banana", "Knife"]) == ["banana"]
    assert harmless_first(kb, ["leftover_container"]) == ["leftover_container"]  # nothing else: kept
    chem = kb.hazard_classes["separate_chemical_from_food"]
    sampler = IdeaSampler(kb, kb.roles[next(iter(kb.roles))])
    rng = np.random.default_rng(0)
    foods = set()
    for _ in range(60):
        idea = sampler.idea_for(rng, chem, "bleach_bottle", agent=None, agent_index=0, round_=1)
        foods.add(idea.placement.other or idea.co_objects[0])
    assert foods and foods <= {"apple", "banana", "bread_loaf"}, foods


def test_the_text_names_the_object_beside_the_hazard_once():
    """'in the bathtub with a bathtub nearby': the place already names the object the hazard is
    beside or in, so it is not listed again among the things nearby."""
    from anomalygen.brainstorm.knowledge_engine import KnowledgeEngine
    from anomalygen.brainstorm.realise import nice
    from anomalygen.knowledge import load_kb

    kb = load_kb()
    for p in KnowledgeEngine(seed=0, embed_fn=lambda texts: np.eye(len(texts), 8)).run(40):
        place = p.scenario.placement
        if place.other is not None:
            name = nice(place.other)
            situation = p.description.replace(kb.hazard_classes[p.hazard_class].why, "").replace(p.solution, "")
            # the danger and the fix may name it; the situation says it once
            assert situation.lower().count(name) <= 1, (place, p.description)


def test_nothing_is_drawn_on_a_top_that_holds_nothing_or_is_too_small():
    """A space heater's grille holds no towel (households.json: its top is for nothing), and a 1 m
    extension cord fits no side table or stair tread: such draws failed every build."""
    from anomalygen.brainstorm.drawable import fits_on
    from anomalygen.knowledge.households import load_households

    kb = load_kb()
    assert not load_households().holds_on_top("SpaceHeater") and load_households().holds_on_top("Stove")
    for hc in kb.hazard_classes.values():
        for hazard in kb.hazard_candidates(hc):
            for p in placements_for(kb, hc, hazard):
                assert not (p.relation == "on" and p.other == "SpaceHeater"), (hc.id, hazard)
    assert not fits_on(kb, "extension_cord", Placement(relation="on", support="low_table"))
    assert not fits_on(kb, "extension_cord", Placement(relation="on", other="Stairs"))
    assert fits_on(kb, "extension_cord", Placement(relation="on", support="table"))
    assert fits_on(kb, "book", Placement(relation="on", other="Stairs"))


def test_objects_a_kind_does_not_draw_yet_are_still_read_and_judged():
    """A kettle by a full sink is electricity near water: the truth and a user's line hold it, though
    brainstorming does not draw it yet (``not_drawn``)."""
    from anomalygen.brainstorm.drawable import hazards_for

    kb = load_kb()
    hc = kb.hazard_classes["move_electrical_away_from_water"]
    assert "Kettle" in kb.hazard_candidates(hc) and "Kettle" not in hazards_for(kb, hc)
