"""Detection scored against truth manifests: recall, precision, F1, hit@k on single-hazard scenes, false alarms."""

from __future__ import annotations

import pytest

from anomalygen.referee.score import claim_matches, score_detections
from anomalygen.schema import Detection, HazardManifest, Hypothesis, ManifestHazard


def hyp(rank, target, cls=None, score=1.0):
    return Hypothesis(rank=rank, problem="p", solution="s", target_object=target, hazard_class=cls, score=score)


def hazard(obj, cls, category):
    return ManifestHazard(hazard_class=cls, object=obj, category=category, severity=0.5, variable="$hazard")


def manifest(task_id, *hazards):
    return HazardManifest(scene_id=f"s-{task_id}", task_id=task_id, hazards=list(hazards))


def detection(task_id, *hyps):
    return Detection(task_id=task_id, scene_id=f"s-{task_id}", detector="rules", hypotheses=list(hyps))


def test_a_claim_names_the_object_and_may_not_contradict_the_class():
    assert claim_matches(hyp(1, "Kitchen_Knife_0", "store_sharp_objects"), "kitchen_knife_0", "store_sharp_objects", "kitchen_knife")
    assert claim_matches(hyp(1, "kitchen_knife", None), "kitchen_knife_0", "store_sharp_objects", "kitchen_knife")
    assert not claim_matches(hyp(1, "kitchen_knife_0", "pick_up_floor_litter"), "kitchen_knife_0", "store_sharp_objects", "kitchen_knife")
    assert not claim_matches(hyp(1, "mug_0", "store_sharp_objects"), "kitchen_knife_0", "store_sharp_objects", "kitchen_knife")


def test_scores_pool_hazards_and_claims_over_single_multi_and_hazard_free_scenes():
    manifests = {
        "one": manifest("one", hazard("knife_0", "store_sharp_objects", "kitchen_knife")),
        "two": manifest("two", hazard("pill_0", "secure_medications", "pill_bottle"),
                        hazard("fridge_0", "close_open_refrigerator", "Refrigerator")),
        "none": manifest("none"),
        "none2": manifest("none2"),
    }
    detections = [
        # the knife at rank 2 (rank 1 is a false claim about the mug)
        detection("one", hyp(1, "mug_0", "move_fragile_from_edge"), hyp(2, "knife_0", "store_sharp_objects")),
        # one of two hazards found, the same claim repeated counts once
        detection("two", hyp(1, "pill_0", "secure_medications"), hyp(2, "pill_0", "secure_medications")),
        detection("none", hyp(1, "cup_0", "move_fragile_from_edge")),  # a false alarm
        detection("none2"),  # silent on a safe scene
        detection("unjudged", hyp(1, "x_0", "y")),  # no manifest: not scored
    ]
    s = score_detections(detections, manifests, k=3)
    assert (s.scenes, s.hazards, s.found, s.claims, s.true_claims) == (4, 3, 2, 4, 2)
    assert s.recall == pytest.approx(2 / 3, abs=1e-4) and s.precision == pytest.approx(0.5)
    assert s.f1 == pytest.approx(2 * (2 / 3) * 0.5 / (2 / 3 + 0.5), abs=1e-4)
    assert s.single_hazard_scenes == 1 and s.hit_at_k == {1: 0.0, 2: 1.0, 3: 1.0}
    assert s.hazard_free_scenes == 2 and s.false_alarm_rate == 0.5


def test_no_hazard_free_scene_gives_no_false_alarm_rate():
    s = score_detections([detection("a", hyp(1, "k_0", "c"))], {"a": manifest("a", hazard("k_0", "c", "k"))}, k=1)
    assert s.false_alarm_rate is None and s.recall == 1.0 and s.precision == 1.0 and s.f1 == 1.0


def test_naming_another_class_that_holds_for_the_object_is_a_true_claim_but_finds_nothing_new():
    """A bleach bottle beside the crib is also within a child's reach: the truth lists the builder's
    class and says the other also fires; claiming it is not a false claim, and recall still asks for
    the listed class."""
    z = hazard("bleach_0", "chemical_near_crib", "bleach_bottle").model_copy(
        update={"also_fires": ["keep_chemicals_from_children"]})
    only_other = score_detections([detection("a", hyp(1, "bleach_0", "keep_chemicals_from_children"))],
                                  {"a": manifest("a", z)}, k=1)
    assert (only_other.claims, only_other.true_claims, only_other.found) == (1, 1, 0)
    wrong = score_detections([detection("a", hyp(1, "bleach_0", "pick_up_floor_litter"))], {"a": manifest("a", z)}, k=1)
    assert wrong.true_claims == 0


def test_the_truth_lists_every_other_class_that_fires_on_the_object_at_fault():
    from tests.knowledge.graphs import graph, obj
    from tests.knowledge.test_mechanisms import NEAR, crib

    from anomalygen.knowledge import load_kb
    from anomalygen.schema import SceneSpec
    from anomalygen.truth.manifest import hazard_manifest

    g = graph(obj("pod_0", "detergent_pod", at="floor", xy=NEAR), crib())
    spec = SceneSpec.model_construct(scene_id="s", task_id="t", bindings={"$hazard": "pod_0", "$crib": "crib_0"})
    m = hazard_manifest(spec, "chemical_near_crib", g, load_kb())
    (pod,) = [h for h in m.hazards if h.object == "pod_0"]
    assert pod.hazard_class == "chemical_near_crib" and "keep_chemicals_from_children" in pod.also_fires
