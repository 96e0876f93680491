"""The referee judges a fix against the truth manifest on the final scene graph (hand-built graphs)."""

from __future__ import annotations

from anomalygen.referee.verdict import verdict_on
from anomalygen.schema import HazardManifest, ManifestHazard, NearMiss, Relation, SceneGraph
from anomalygen.truth.manifest import bound_success, class_matches
from detect import detect_graphs as g  # tests/detect/detect_graphs.py: the hand-built scene graphs


def knife_manifest(kb) -> HazardManifest:
    hc = kb.hazard_classes["store_sharp_objects"]
    bindings = {"$hazard": "kitchen_knife_0", "$container": "storage_0"}
    return HazardManifest(
        scene_id="s-knife", task_id="t", hazards=[ManifestHazard(
            hazard_class=hc.id, object="kitchen_knife_0", category="kitchen_knife", severity=hc.severity,
            variable="$hazard", bindings=bindings, success=bound_success(hc, "$hazard", "kitchen_knife_0", bindings))],
        near_misses=[NearMiss(object="mug_0", category="mug", looks_like="move_fragile_from_edge", why_safe="far from the edge")],
    )


def moved(graph: SceneGraph, name: str, **update) -> SceneGraph:
    objs = [o.model_copy(update=update) if o.name == name else o for o in graph.objects]
    return graph.model_copy(update={"objects": objs})


def test_success_binds_the_object_at_fault_and_leaves_the_fixs_choices_open(kb):
    manifest = knife_manifest(kb)
    (call,) = manifest.hazards[0].success
    assert call.name == "inside" and call.args == {"object": "kitchen_knife_0", "container": "*"}
    perishable = kb.hazard_classes["store_perishable_food"]
    calls = bound_success(perishable, "$hazard", "milk_0", {"$hazard": "milk_0", "$container": "refrigerator_0"})
    assert [c.name for c in calls] == ["inside"]  # the container's door is the fix's choice: left out


def test_a_knife_shut_in_a_drawer_is_resolved_and_one_left_on_the_edge_is_not(kb):
    start = g.knife_on_counter_edge()
    manifest = knife_manifest(kb)
    unresolved = verdict_on(manifest, start, start, kb, task_id="t")
    assert not unresolved.resolved and unresolved.status == "unresolved"
    assert unresolved.hazards[0].still_firing == ["store_sharp_objects"]
    assert "store_sharp_objects fires on kitchen_knife_0" in unresolved.hazards[0].detail
    stored = moved(start, "kitchen_knife_0", position=[2.6, 1.6, 0.5], height_above_floor=0.4, distance_to_edge=None,
                   child_reachable=False)
    stored = stored.model_copy(update={"relations": [r for r in start.relations if r.subject != "kitchen_knife_0"]
                                       + [Relation(subject="kitchen_knife_0", predicate="inside", object="storage_0")]})
    verdict = verdict_on(manifest, start, stored, kb, task_id="t", seed=0)
    assert verdict.resolved and verdict.status == "resolved" and verdict.hazards[0].detail == "fixed"
    assert verdict.new_hazards == [] and verdict.interventions_on_safe == []


def test_a_knife_dropped_to_the_floor_is_a_new_hazard_and_moving_the_mug_an_intervention_on_a_safe_object(kb):
    start = g.knife_on_counter_edge()
    final = moved(start, "kitchen_knife_0", position=[0.6, 1.1, 0.01], height_above_floor=0.0, on_floor=True,
                  distance_to_edge=None)
    final = moved(final, "mug_0", position=[0.2, 1.7, 0.925])  # pushed 10 cm along the counter
    final = final.model_copy(update={"relations": [r for r in start.relations if r.subject != "kitchen_knife_0"]
                                     + [Relation(subject="kitchen_knife_0", predicate="on_floor")]})
    assert ("keep_sharp_away_from_children", "kitchen_knife_0") not in {(c, o) for c, o, _ in class_matches(start, kb)}
    verdict = verdict_on(knife_manifest(kb), start, final, kb, task_id="t")
    assert "keep_sharp_away_from_children on kitchen_knife_0" in verdict.new_hazards, verdict
    assert verdict.interventions_on_safe == ["mug_0"]
    # off the edge, yet within a child's reach: the knife's own hazard is not resolved either
    assert verdict.hazards[0].still_firing == ["keep_sharp_away_from_children"] and not verdict.resolved


def _hazard_free(kb) -> HazardManifest:
    return HazardManifest(scene_id="s", task_id="t", hazards=[], near_misses=[
        NearMiss(object="mug_0", category="mug", looks_like="move_fragile_from_edge", why_safe="far from the edge")])


def _without_knife(graph: SceneGraph) -> SceneGraph:
    """The counter scene with the knife already shut away: nothing in it is a hazard."""
    stored = moved(graph, "kitchen_knife_0", position=[2.6, 1.6, 0.5], height_above_floor=1.2, distance_to_edge=None,
                   child_reachable=False)
    return stored.model_copy(update={"relations": [r for r in graph.relations if r.subject != "kitchen_knife_0"]
                                     + [Relation(subject="kitchen_knife_0", predicate="inside", object="storage_0")]})


def test_a_hazard_free_scene_is_never_resolved_left_alone_is_no_action_needed(kb):
    start = _without_knife(g.knife_on_counter_edge())
    assert class_matches(start, kb) == []
    v = verdict_on(_hazard_free(kb), start, start, kb, task_id="t", seed=0)
    assert (v.status, v.resolved, v.hazards, v.new_hazards) == ("no_action_needed", False, [], [])


def test_a_hazard_free_scene_touched_or_harmed_is_acted_on_safe_never_resolved(kb):
    start = _without_knife(g.knife_on_counter_edge())
    nudged = moved(start, "mug_0", position=[0.2, 1.7, 0.925])
    v = verdict_on(_hazard_free(kb), start, nudged, kb, task_id="t")
    assert (v.status, v.resolved, v.interventions_on_safe) == ("acted_on_safe", False, ["mug_0"])
    dropped = moved(start, "kitchen_knife_0", position=[0.6, 1.1, 0.01], height_above_floor=0.0, on_floor=True,
                    child_reachable=True)
    dropped = dropped.model_copy(update={"relations": [r for r in start.relations if r.subject != "kitchen_knife_0"]})
    v = verdict_on(_hazard_free(kb), start, dropped, kb, task_id="t")
    assert v.status == "acted_on_safe" and not v.resolved
    assert "keep_sharp_away_from_children on kitchen_knife_0" in v.new_hazards


def test_a_fixed_hazard_with_a_new_hazard_beside_it_is_an_unresolved_run(kb):
    start = g.knife_on_counter_edge()
    fixed = _without_knife(start)
    fixed = moved(fixed, "mug_0", position=[0.6, 1.2, 0.05], height_above_floor=0.0, on_floor=True, distance_to_edge=None)
    v = verdict_on(knife_manifest(kb), start, fixed, kb, task_id="t")
    assert v.hazards[0].resolved and v.new_hazards and v.status == "unresolved" and not v.resolved


def test_the_container_a_hazard_was_stored_in_is_used_for_the_fix_not_an_intervention_on_a_safe_object(kb):
    """The cabinet is a state near-miss (shut); the robot opens it, shuts the knife in and leaves its
    door 0.3 rad open: that is no needless intervention, but the open door is a new hazard."""
    manifest = knife_manifest(kb).model_copy(update={"near_misses": [
        NearMiss(object="storage_0", category="StorageFurniture", looks_like="close_open_furniture",
                 why_safe="shut", kind="state")]})
    start = g.knife_on_counter_edge()
    stored = _without_knife(start)
    ajar = [j.model_copy(update={"value": 0.3}) for j in next(o for o in stored.objects if o.name == "storage_0").joints]
    final = moved(stored, "storage_0", joints=ajar)
    verdict = verdict_on(manifest, start, final, kb, task_id="t")
    assert verdict.interventions_on_safe == []
    # the same door moved with nothing stored in the cabinet is an intervention on a safe object
    emptied = final.model_copy(update={"relations": [r for r in final.relations if r.subject != "kitchen_knife_0"]})
    assert verdict_on(manifest, start, emptied, kb, task_id="t").interventions_on_safe == ["storage_0"]


def _iron_by_magazine(switch: float) -> SceneGraph:
    from knowledge.graphs import furniture, graph, joint, obj

    return graph(obj("iron_0", "iron", at="floor", xy=(0.0, 0.0), size=(0.19, 0.28, 0.1), joints=[joint("switch", switch)]),
                 obj("magazine_0", "magazine", at="floor", xy=(0.0, 0.2), size=(0.3, 0.1, 0.01)),
                 furniture("table_0", "Table", xy=(0.0, 0.65), size=(1.4, 0.6, 0.76)))  # both tucked by a table


def _iron_manifest(kb) -> HazardManifest:
    """t0008's truth: one danger (a hot iron beside a magazine) recorded from each object's side."""
    def hazard(cid, var, name, bindings, source):
        hc = kb.hazard_classes[cid]
        return ManifestHazard(hazard_class=cid, object=name, category=name[:-2], severity=hc.severity, variable=var,
                              bindings=bindings, success=bound_success(hc, var, name, bindings), source=source)
    return HazardManifest(scene_id="s-iron", task_id="t", hazards=[
        hazard("switch_off_heater_near_fabric", "$hazard", "iron_0", {"$hazard": "iron_0", "$fuel": "magazine_0"}, "intended"),
        hazard("clear_burning_risk_near_heat_source", "$hazard", "magazine_0",
               {"$hazard": "magazine_0", "$source": "iron_0"}, "incidental")])


def _iron_fixed_magazine_not(manifest: HazardManifest) -> list:
    """The verdicts before the same-danger pass: the iron's hazard fixed, the magazine's own check failed."""
    from anomalygen.schema import HazardVerdict

    return [HazardVerdict(hazard_class=h.hazard_class, object=h.object, source=h.source, resolved=i == 0,
                          detail="fixed" if i == 0 else "magazine_0 rests on nothing") for i, h in enumerate(manifest.hazards)]


def test_one_danger_seen_from_two_objects_is_fixed_once(kb):
    """t0008 at d48b921: the iron was switched off, which ends the danger, yet the magazine's own
    success (taken off the floor onto a support) failed the run. Its objects all take part in the
    iron's hazard, which was fixed, and no class fires on the magazine any more."""
    start = _iron_by_magazine(0.9)
    assert {("switch_off_heater_near_fabric", "iron_0"), ("clear_burning_risk_near_heat_source", "magazine_0")} <= {
        (c, o) for c, o, _ in class_matches(start, kb)}
    verdict = verdict_on(_iron_manifest(kb), start, _iron_by_magazine(0.0), kb, task_id="t")
    assert verdict.resolved, verdict.hazards
    assert "the same danger" in verdict.hazards[1].detail
    left_on = verdict_on(_iron_manifest(kb), start, start, kb, task_id="t")
    assert not left_on.resolved and not any(h.resolved for h in left_on.hazards)


def test_a_hazard_is_not_let_off_by_a_fix_that_leaves_its_own_objects_out(kb):
    """Only a fixed hazard that involves every object of the other one covers it: the iron's fix
    does not cover a hazard on a third object."""
    from anomalygen.referee.verdict import _same_danger_fixed

    manifest = _iron_manifest(kb)
    other = manifest.hazards[1].model_copy(update={"bindings": {"$hazard": "magazine_0", "$source": "stove_0"}})
    manifest = manifest.model_copy(update={"hazards": [manifest.hazards[0], other]})
    verdicts = _iron_fixed_magazine_not(manifest)
    final = _iron_by_magazine(0.0)
    assert [v.resolved for v in _same_danger_fixed(manifest, verdicts, final, kb)] == [True, False]


def test_a_hazard_that_ended_on_its_own_object_is_not_let_off(kb):
    """The iron's hazard fixed, but the magazine's hazard ended because the magazine itself moved (its
    near-the-iron precondition fails), not because the iron was put right: its own success decides."""
    from anomalygen.referee.verdict import _same_danger_fixed

    manifest = _iron_manifest(kb)
    moved_off = moved(_iron_by_magazine(0.9), "magazine_0", position=[2.0, 0.2, 0.005])
    verdicts = _iron_fixed_magazine_not(manifest)
    assert [v.resolved for v in _same_danger_fixed(manifest, verdicts, moved_off, kb)] == [True, False]
