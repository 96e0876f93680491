"""Optional perception noise (``detect.noise``): off leaves the graph alone; on, it is deterministic
under the seed, moves positions within the jitter bound, drops only small objects at the configured
rate, confuses only look-alikes, and the detect stage records the settings it used."""

from __future__ import annotations

import detect_graphs as g
import numpy as np
import pytest

from anomalygen.config import Settings, load_settings
from anomalygen.detect.noise import add_noise, detector_graph, noise_rng
from anomalygen.detect.stage import run_stage
from anomalygen.knowledge import load_kb
from anomalygen.runfolder import RunFolder, read_jsonl, write_jsonl, write_model
from anomalygen.schema import Detection, Relation, SceneGraph, SceneSpec

SMALL = 0.06  # m: the default small_size


def _graph(n_small: int = 120) -> SceneGraph:
    """Furniture, a knife near the counter's edge, and many small look-alike and plain objects."""
    cats = ["coin", "button_battery", "marble", "toy_block", "pill"]  # all small, all with look-alikes
    small = [g.on_surface(f"{cats[i % len(cats)]}_{i}", cats[i % len(cats)], None, 0.75,
                          (1.2 + 0.004 * i, 0.3 + 0.003 * i), size=(0.02, 0.02, 0.01)) for i in range(n_small)]
    knife = g.on_surface("kitchen_knife_0", "kitchen_knife", None, 0.9, (0.5, 1.36), edge=0.03, size=(0.25, 0.03, 0.02))
    objects = [*g.kitchen_furniture(), knife, *small]
    relations = [Relation(subject="kitchen_knife_0", predicate="on", object="counter_0"),
                 *(Relation(subject=o.name, predicate="on", object="table_0") for o in small)]
    return SceneGraph(scene_id="scene_noise", room="kitchen", objects=objects, relations=relations)


def _noisy(graph, seed=0, **cfg):
    s = Settings(seed=seed, detect={"noise": {"enabled": True, **cfg}})
    return detector_graph(graph, s)


def test_noise_off_gives_the_identical_graph():
    graph = _graph()
    seen, record = detector_graph(graph, Settings())
    assert seen is graph and record is None


def test_noise_on_is_deterministic_under_the_seed():
    graph = _graph()
    a, ra = _noisy(graph, seed=3)
    b, rb = _noisy(graph, seed=3)
    c, _ = _noisy(graph, seed=4)
    assert a == b and ra == rb and ra.seed == 3
    assert a != c


def test_jitter_moves_positions_within_the_bound_and_what_follows_from_them():
    graph = _graph()
    seen, record = _noisy(graph, pose_jitter=0.05, miss_rate=0.0, confusion_rate=0.0)
    assert record.missed == record.confused == 0 and len(seen.objects) == len(graph.objects)
    moved = 0
    for before, after in zip(graph.objects, seen.objects, strict=True):
        d = np.asarray(after.position) - np.asarray(before.position)
        assert np.all(np.abs(d) <= 0.05 + 1e-12), before.name
        moved += bool(np.any(np.abs(d) > 1e-4))
        assert after.height_above_floor == pytest.approx(max(0.0, before.height_above_floor + d[2]))
        if before.distance_to_edge is not None and before.name == "kitchen_knife_0":
            # the counter's own box moves too: the gap to its edge changes by at most both bounds
            assert abs(after.distance_to_edge - before.distance_to_edge) <= 2 * 0.05 + 1e-12
    assert moved == len(graph.objects)


def test_jitter_redraws_a_childs_reach_by_the_graphs_rule():
    """A child reaches an object whose bottom is at most CHILD_REACH up, unless it is shut in a latching
    container: a low pill bottle locked away stays out of reach, one in a plain cupboard stays within
    it, and bottles near the threshold, loose or in a plain cupboard, are judged at their jittered height."""
    from anomalygen.schema import CHILD_REACH

    locked = g.obj("pill_bottle_0", "pill_bottle", pos=(1.0, 1.0, 0.35), size=(0.05, 0.05, 0.1), reach=False)
    cupboard = g.obj("pill_bottle_1", "pill_bottle", pos=(2.0, 1.0, 0.35), size=(0.05, 0.05, 0.1), reach=True)
    loose = g.on_surface("pill_bottle_2", "pill_bottle", None, CHILD_REACH - 0.01, (3.0, 1.0), size=(0.05, 0.05, 0.1))
    shelf = g.on_surface("pill_bottle_3", "pill_bottle", None, CHILD_REACH - 0.01, (4.0, 1.0), size=(0.05, 0.05, 0.1))
    graph = g.scene("scene_reach", "bathroom", [locked, cupboard, loose, shelf], [
        Relation(subject="pill_bottle_0", predicate="inside", object="medicine_cabinet_0"),
        Relation(subject="pill_bottle_1", predicate="inside", object="cabinet_0"),
        Relation(subject="pill_bottle_3", predicate="inside", object="cabinet_1")])
    assert loose.child_reachable and shelf.child_reachable
    flips = {"pill_bottle_2": 0, "pill_bottle_3": 0}
    for seed in range(20):
        seen, _ = _noisy(graph, seed=seed, pose_jitter=0.05, miss_rate=0.0, confusion_rate=0.0)
        by = {o.name: o for o in seen.objects}
        assert not by["pill_bottle_0"].child_reachable and by["pill_bottle_1"].child_reachable
        for name in flips:  # a plain cupboard's door keeps nothing from a toddler: only the height counts
            assert by[name].child_reachable == (by[name].height_above_floor <= CHILD_REACH), (seed, name)
            flips[name] += not by[name].child_reachable
    assert all(0 < n < 20 for n in flips.values()), flips  # the threshold is crossed both ways


def test_only_small_objects_are_missed_at_the_configured_rate():
    graph = _graph(n_small=400)
    small = {o.name for o in graph.objects if max(o.size) <= SMALL}
    seen, record = _noisy(graph, pose_jitter=0.0, miss_rate=0.3, confusion_rate=0.0)
    names = {o.name for o in seen.objects}
    missed = {o.name for o in graph.objects} - names
    assert missed <= small and record.missed == len(missed) and record.objects == len(graph.objects)
    assert 0.24 <= len(missed) / len(small) <= 0.36  # 400 draws at 0.3
    assert all(r.subject in names and (r.object or "").split(":")[0] in names | {""} for r in seen.relations)
    none, _ = _noisy(graph, pose_jitter=0.0, miss_rate=0.0, confusion_rate=0.0)
    assert len(none.objects) == len(graph.objects)


def test_confusions_stay_within_look_alike_groups():
    kb = load_kb()
    graph = _graph()
    seen, record = _noisy(graph, pose_jitter=0.0, miss_rate=0.0, confusion_rate=1.0)
    confused = 0
    for before, after in zip(graph.objects, seen.objects, strict=True):
        alike = kb.lookalikes(before.category)
        if not alike:
            assert after.category == before.category, before.name  # furniture: never confused
            continue
        assert after.category in alike and after.properties == kb.properties_of(after.category)
        assert after.name == before.name  # the handle the robot acts through stays
        confused += 1
    assert confused == record.confused > 0
    half, _ = add_noise(graph, Settings().detect.noise.model_copy(update={"pose_jitter": 0.0, "miss_rate": 0.0,
                        "confusion_rate": 0.5}), noise_rng(0, graph.scene_id), kb, 0)
    changed = sum(a.category != b.category for a, b in zip(graph.objects, half.objects, strict=True))
    assert 0 < changed < confused


def test_detect_stage_records_the_noise_and_redoes_detections_when_it_changes(tmp_path):
    run = RunFolder.create(tmp_path / "run")
    write_jsonl(run.tasks_path, [g.KNIFE_TASK])
    graph = g.knife_on_counter_edge()
    d = run.scene_dir(g.KNIFE_TASK.id)
    write_model(d / "scene_graph.json", graph)
    write_model(d / "scene.json", SceneSpec(scene_id=graph.scene_id, task_id=g.KNIFE_TASK.id, room=graph.room,
                                            seed=0, objects=[], bindings={"$hazard": "kitchen_knife_0"}))
    off = load_settings(None, {"quiet": True, "workers": 1})
    on = load_settings(None, {"quiet": True, "workers": 1, "detect.noise.enabled": True, "detect.noise.pose_jitter": 0.01})
    assert run_stage(run, off).done == 1
    assert read_jsonl(run.detections_path, Detection)[0].noise is None
    assert run_stage(run, off).skipped == 1
    assert run_stage(run, on).done == 1  # other noise settings: detected again
    (det,) = read_jsonl(run.detections_path, Detection)
    assert det.noise is not None and det.noise.pose_jitter == 0.01 and det.noise.objects == len(graph.objects)
    assert run_stage(run, on).skipped == 1
