"""The text judge (a diagnostic): exact object+class hits, calibrated SBERT for free text, honest reasons."""

from __future__ import annotations

import json

import numpy as np
import pytest

from anomalygen.evaluate.detection_scores import ground_truth
from anomalygen.evaluate.judge_calibration import calibrate, calibration_path, load_pairs
from anomalygen.evaluate.text_judge import Judge, best_threshold, calibrated_threshold, first_hit
from anomalygen.schema import Hypothesis, SceneSpec
from detect import detect_graphs as g  # tests/detect/detect_graphs.py: the hand-built scene graphs


def hyp(rank, obj, cls, problem="p", solution="s"):
    return Hypothesis(rank=rank, problem=problem, solution=solution, target_object=obj, hazard_class=cls)


def spec_for(graph, **bindings):
    return SceneSpec(scene_id=graph.scene_id, task_id="t", room=graph.room, seed=0, objects=[], bindings=bindings)


def test_truth_comes_from_the_scene_bindings():
    graph = g.knife_on_counter_edge()
    truth = ground_truth(g.KNIFE_TASK, spec_for(graph, **{"$hazard": "kitchen_knife_0", "$target": "counter_0"}), graph)
    assert truth.instances == {"kitchen_knife_0"} and truth.categories == {"kitchen_knife"}
    assert truth.names_object("kitchen_knife_0", graph) and truth.names_object("Kitchen_Knife", graph)
    assert not truth.names_object("counter_0", graph)  # $target is not the hazard here
    fridge = g.open_fridge()
    t2 = ground_truth(g.FRIDGE_TASK, spec_for(fridge, **{"$target": "refrigerator_0"}), fridge, hazard_variable="$target")
    assert t2.names_object("refrigerator_0:door", fridge) and t2.names_object("refrigerator", fridge)


def test_exact_hit_needs_object_and_class():
    graph = g.two_hazards()
    truth = ground_truth(g.KNIFE_TASK, spec_for(graph, **{"$hazard": "kitchen_knife_0"}), graph)
    hyps = [
        hyp(1, "marble_0", "remove_choking_hazards"),
        hyp(2, "kitchen_knife_0", "keep_sharp_away_from_children"),
        hyp(3, "kitchen_knife_0", "store_sharp_objects"),
    ]
    js = Judge(threshold=0.6).judge(hyps, truth, graph)
    assert [j.hit for j in js] == [False, False, True]
    assert all(j.method == "exact" for j in js)
    assert "other object and class" in js[0].reason and "wrong class" in js[1].reason
    assert first_hit(js) == 3


def test_another_instance_of_the_same_category_is_not_the_hazard():
    graph = g.knife_on_counter_edge()
    graph = graph.model_copy(update={"objects": graph.objects + [g.obj("kitchen_knife_1", "kitchen_knife")]})
    truth = ground_truth(g.KNIFE_TASK, spec_for(graph, **{"$hazard": "kitchen_knife_0"}), graph)
    js = Judge(threshold=0.6).judge([hyp(1, "kitchen_knife_1", "store_sharp_objects")], truth, graph)
    assert not js[0].hit and "right class, wrong object" in js[0].reason


def test_free_text_is_judged_by_calibrated_similarity():
    graph = g.knife_on_counter_edge()
    truth = ground_truth(g.KNIFE_TASK, spec_for(graph, **{"$hazard": "kitchen_knife_0"}), graph)
    good = hyp(1, "kitchen_knife_0", None, "A sharp knife is lying at the edge of the worktop and could fall on someone",
               "Put the knife away in the cabinet")
    bad = hyp(2, "mug_0", None, "The mug is dirty", "Wash the mug in the sink")
    js = Judge().judge([good, bad], truth, graph)
    assert js[0].hit and js[0].method == "sbert" and js[0].similarity >= calibrated_threshold()
    assert not js[1].hit and js[1].similarity < calibrated_threshold()


def test_llm_detector_class_slip_falls_back_to_text_when_not_decisive():
    graph = g.knife_on_counter_edge()
    truth = ground_truth(g.KNIFE_TASK, spec_for(graph, **{"$hazard": "kitchen_knife_0"}), graph)
    h = hyp(1, "kitchen_knife_0", "keep_sharp_away_from_children",
            "The chef's knife is balanced at the front lip of the worktop and could fall blade first",
            "Lay the knife inside the storage cabinet")
    assert not Judge(structured_decisive=True).judge([h], truth, graph)[0].hit
    assert Judge(structured_decisive=False).judge([h], truth, graph)[0].method == "sbert"


def test_calibration_set_is_big_balanced_and_hard():
    pairs = load_pairs()
    assert len(pairs) >= 100
    kinds = {p.kind for p in pairs}
    assert {"positive", "same_object_wrong_hazard", "same_hazard_wrong_object", "different_problem"} <= kinds
    assert 0.3 <= np.mean([p.hit for p in pairs]) <= 0.6
    assert len({p.id for p in pairs}) == len(pairs)


def test_best_threshold_separates_separable_scores():
    sims = np.array([0.2, 0.3, 0.4, 0.7, 0.8, 0.9])
    labels = np.array([False, False, False, True, True, True])
    t, p, r, f = best_threshold(sims, labels)
    assert 0.4 < t < 0.7 and p == r == f == 1.0


@pytest.mark.slow
def test_stored_threshold_is_the_calibrated_one_and_good():
    """Re-derives threshold.json from the labelled set; the judge's precision and recall stay high."""
    result = calibrate(load_pairs())
    stored = json.loads(calibration_path().with_name("threshold.json").read_text())
    assert abs(stored["threshold"] - result.threshold) < 1e-3
    assert calibrated_threshold() == pytest.approx(result.threshold, abs=1e-3)
    assert result.precision >= 0.85 and result.recall >= 0.85
    assert result.cv_precision >= 0.8 and result.cv_recall >= 0.8
    # hard negatives with a different object are never judged hits
    assert result.per_kind["same_hazard_wrong_object"]["judged_hit_rate"] <= 0.05
    assert result.per_kind["different_problem"]["judged_hit_rate"] <= 0.05
