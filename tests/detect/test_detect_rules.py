"""The rule detector on hand-built scenes: right class on the right object, ranked, explained, robust."""

from __future__ import annotations

import detect_graphs as g
import pytest

from anomalygen.detect.rules import Candidate, RuleDetector, candidates, rank
from anomalygen.schema import Relation


@pytest.mark.parametrize(
    ("graph_fn", "obj", "cls"),
    [
        (g.knife_on_counter_edge, "kitchen_knife_0", "store_sharp_objects"),
        (g.pill_on_floor, "pill_bottle_0", "secure_medications"),
        (g.open_fridge, "refrigerator_0", "close_open_refrigerator"),
    ],
)
def test_top1_is_the_hazard(kb, graph_fn, obj, cls):
    hyps = RuleDetector(kb).detect(graph_fn(), 3)
    assert (hyps[0].target_object, hyps[0].hazard_class) == (obj, cls)
    assert hyps[0].rank == 1
    # explained in words from the predicates that fired
    assert hyps[0].explanation.startswith(f"{cls} holds because ")
    assert obj in hyps[0].explanation and obj in hyps[0].problem
    assert hyps[0].solution and "{" not in hyps[0].solution


def test_a_safe_kitchen_raises_nothing(kb):
    assert RuleDetector(kb).detect(g.scene("s-safe", "kitchen", g.kitchen_furniture()), 3) == []


def test_two_hazards_are_both_in_the_top3(kb):
    hyps = RuleDetector(kb).detect(g.two_hazards(), 3)
    found = {(h.target_object, h.hazard_class) for h in hyps}
    assert ("kitchen_knife_0", "store_sharp_objects") in found
    assert ("marble_0", "remove_choking_hazards") in found


def test_knife_on_the_floor_is_a_child_hazard_not_a_trip_hazard(kb):
    base = g.kitchen_furniture()
    knife = g.obj("kitchen_knife_0", "kitchen_knife", pos=(1.0, -0.5, 0.01), size=(0.3, 0.04, 0.02))
    hyps = RuleDetector(kb).detect(g.scene("s", "kitchen", base + [knife]), 3)
    assert hyps[0].hazard_class == "keep_sharp_away_from_children"
    assert all(h.hazard_class != "reduce_tripping_hazards" for h in hyps)


@pytest.mark.parametrize("graph_fn", [g.knife_on_counter_edge, g.pill_on_floor, g.open_fridge, g.two_hazards])
def test_five_clutter_objects_do_not_change_the_answer(kb, graph_fn):
    det = RuleDetector(kb)
    plain = det.detect(graph_fn(), 3)
    cluttered = det.detect(g.add_clutter(graph_fn(), 5), 3)
    assert [(h.target_object, h.hazard_class) for h in cluttered] == [(h.target_object, h.hazard_class) for h in plain]


def test_deterministic_and_deduplicated(kb):
    graph = g.two_hazards()
    # a second container candidate must not give a second hypothesis for the same object and class
    graph = graph.model_copy(update={"relations": graph.relations + [Relation(subject="marble_0", predicate="near", object="table_0")]})
    runs = [RuleDetector(kb).detect(graph, 10) for _ in range(3)]
    assert runs[0] == runs[1] == runs[2]
    keys = [(h.target_object, h.hazard_class) for h in runs[0]]
    assert len(keys) == len(set(keys))
    assert [h.rank for h in runs[0]] == list(range(1, len(keys) + 1))


def test_ranking_prefers_severity_then_covers_other_objects():
    def cand(obj, cls, score):
        return Candidate(hazard_class=cls, object=obj, category="x", severity=score, score=score, typical=True,
                         specificity=2, problem="p", solution="s", explanation="e", bindings=())

    a1, a2, b1 = cand("a", "c1", 0.9), cand("a", "c2", 0.85), cand("b", "c3", 0.8)
    assert [c.hazard_class for c in rank([b1, a2, a1], 3)] == ["c1", "c3", "c2"]
    # a second class on an object never pushes a different object out of the top k, however much
    # weaker that object's hazard is (the planner fixes one class per object: the cut-off hid litter)
    b_low, a3 = cand("b", "c3", 0.3), cand("a", "c4", 0.84)
    assert [c.hazard_class for c in rank([a1, a2, a3, b_low], 2)] == ["c1", "c3"]
    assert [c.hazard_class for c in rank([a1, a2, a3, b_low], 4)] == ["c1", "c3", "c2", "c4"]
    assert rank([a1, a2, b1], 1) == [a1]


def test_typical_hazard_objects_break_ties(kb):
    """Two objects in the walkway: the shoe (a typical trip hazard) ranks before the cup."""
    assert "shoe" in kb.hazard_classes["reduce_tripping_hazards"].hazard_objects
    assert "cup" not in kb.hazard_classes["reduce_tripping_hazards"].hazard_objects
    floor = [g.obj("cup_0", "cup", pos=(0.9, -0.9, 0.05), size=(0.08, 0.08, 0.1)),
             g.obj("shoe_0", "shoe", pos=(1.4, -0.6, 0.08), size=(0.3, 0.12, 0.16))]
    hyps = RuleDetector(kb).detect(g.scene("s", "bedroom", g.kitchen_furniture() + floor), 2)
    assert [(h.target_object, h.hazard_class) for h in hyps] == [
        ("shoe_0", "reduce_tripping_hazards"), ("cup_0", "reduce_tripping_hazards")]
    assert hyps[0].score == kb.hazard_classes["reduce_tripping_hazards"].severity
    assert hyps[1].score < hyps[0].score and "not a typical object" in hyps[1].explanation


def test_an_incidental_floor_object_does_not_outrank_the_litter(kb):
    """A cup on the floor fires the generic tripping rule, but the wrapper beside it is the problem."""
    floor = [g.obj("cup_0", "cup", pos=(0.9, -0.9, 0.05), size=(0.08, 0.08, 0.1)),
             g.obj("wrapper_0", "wrapper", pos=(1.2, -0.9, 0.01), size=(0.1, 0.08, 0.02))]
    hyps = RuleDetector(kb).detect(g.scene("s", "kitchen", g.kitchen_furniture() + floor), 3)
    assert (hyps[0].target_object, hyps[0].hazard_class) == ("wrapper_0", "pick_up_floor_litter")
    assert ("cup_0", "reduce_tripping_hazards") in [(h.target_object, h.hazard_class) for h in hyps]


def test_candidates_cover_every_kb_class_that_fires(kb):
    hits = candidates(g.two_hazards(), kb)
    assert {c.hazard_class for c in hits} <= set(kb.hazard_classes)
    assert all(c.severity == kb.hazard_classes[c.hazard_class].severity for c in hits)


@pytest.mark.parametrize("n_clutter", [0, 5])
def test_every_hazard_the_kb_can_set_up_is_found_at_rank1(kb, n_clutter):
    """The KB's classes are discriminative: each (class, object, placement) wins on its own scene."""
    from anomalygen.detect.kbcheck import sweep

    result = sweep(kb, n_clutter=n_clutter)
    assert result["cases"] >= 100
    assert result["failures"] == [] and result["top1"] == 1.0
