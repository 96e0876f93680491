"""The plausible-homes table (issue 39): where fixtures belong, shared with the household lexicon, and
a generator that never puts one in the wrong room."""

from __future__ import annotations

import json

import pytest

from anomalygen.knowledge.base import KNOWLEDGE_DIR, ROOMS
from anomalygen.knowledge.households import Households, load_households, misplaced_objects


def test_the_table_loads_and_names_only_real_rooms():
    table = load_households()
    assert {"Bathtub", "Crib", "Stove", "Dishwasher", "Toilet"} <= set(table.fixtures)
    assert all(set(f.rooms) <= set(ROOMS) and f.rooms for f in table.fixtures.values())
    assert table.rooms_of("Bathtub") == ("bathroom",)
    assert not table.belongs("Bathtub", "kitchen") and not table.belongs("Crib", "kitchen")
    assert not table.belongs("Dishwasher", "living_room") and table.belongs("Dishwasher", "kitchen")
    assert table.belongs("knife", "office")  # a portable thing has no rule
    assert table.rooms_for(["Sink", "Stove"], list(ROOMS)) == ["kitchen"]


def test_a_fixture_that_stands_no_known_way_is_refused():
    with pytest.raises(ValueError):
        Households.model_validate({"fixtures": {"Sink": {"rooms": ["kitchen"], "mount": "sideways", "top": "rim"}}})


def test_the_lexicons_fixture_kinds_stand_only_where_a_proxy_belongs():
    """A household kind whose every proxy is a fixture lists only rooms one of those proxies belongs to:
    the lexicon and the table say the same about homes."""
    lexicon = json.loads((KNOWLEDGE_DIR / "lexicon.json").read_text("utf-8"))
    table = load_households()
    for name, kind in lexicon["kinds"].items():
        if kind["proxies"] and all(p in table.fixtures for p in kind["proxies"]):
            rooms = set().union(*(table.fixtures[p].rooms for p in kind["proxies"]))
            assert set(kind["rooms"]) <= rooms, (name, sorted(set(kind["rooms"]) - rooms))


@pytest.mark.slow
def test_no_fixture_stands_in_a_room_where_it_does_not_belong_over_seeds_0_to_9():
    from anomalygen.brainstorm.knowledge_engine import KnowledgeEngine

    bad = []
    for seed in range(10):
        for task in KnowledgeEngine(seed=seed).run(111):
            bad += [f"seed {seed} {task.id}: {n} in {task.scenario.room}" for n in misplaced_objects(task)]
    assert bad == []
