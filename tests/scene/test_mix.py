"""Near-miss distractors and the second hazard: chosen from the scene's own generator, real in the built scene."""

from __future__ import annotations

from anomalygen.config import Settings
from anomalygen.knowledge import load_kb
from anomalygen.scene.mix import (
    BORDER_M,
    SECOND_HAZARD_CLASS,
    choose_judgement_items,
    edge_threshold,
    near_miss_names,
)

from .conftest import make_task


def test_near_misses_are_fragile_or_heavy_things_no_class_flags_on_a_table_middle():
    kb = load_kb()
    names = near_miss_names(kb, set())
    assert {"mug", "vase", "dumbbell"} <= set(names)
    for n in names:
        props = set(kb.objects[n].properties)
        assert props & {"fragile", "heavy"} and not props & {"hot", "sharp", "toxic", "medication", "litter"}


def test_the_mix_is_off_when_asked_and_otherwise_a_function_of_seed_and_task():
    kb = load_kb()
    off = Settings(build={"near_misses": 0, "multi_hazard": 0.0})
    items = choose_judgement_items("t1", "store_sharp_objects", set(), kb, off)
    assert items.near_misses == [] and items.second_hazard is None and items.bin is None
    on = Settings(build={"near_misses": 2, "multi_hazard": 1.0})
    a = choose_judgement_items("t1", "store_sharp_objects", set(), kb, on)
    b = choose_judgement_items("t1", "store_sharp_objects", set(), kb, on)
    assert (a.near_misses, a.second_hazard, a.bin) == (b.near_misses, b.second_hazard, b.bin)
    assert len(a.near_misses) == 2 and a.second_hazard in kb.hazard_candidates(kb.hazard_classes[SECOND_HAZARD_CLASS])
    assert a.state == b.state
    assert a.bin == "TrashCan"
    assert choose_judgement_items("t1", "store_sharp_objects", {"TrashCan"}, kb, on).bin is None
    assert choose_judgement_items("t1", SECOND_HAZARD_CLASS, set(), kb, on).second_hazard is None


def test_borderline_near_misses_straddle_the_edge_rule_by_a_centimetre_and_hazard_free_scenes_get_none_inside():
    kb = load_kb()
    assert edge_threshold(kb, "mug") == ("move_fragile_from_edge", 0.12)
    on = Settings(build={"near_misses": 3, "multi_hazard": 0.0})
    picks = [p for t in range(40) for p in choose_judgement_items(f"t{t}", "store_sharp_objects", set(), kb, on).near_misses]
    kinds = {p.kind for p in picks}
    assert kinds == {"far", "just_outside", "just_inside"}
    for p in picks:
        if p.kind == "far":
            assert p.edge_gap is None
        else:
            limit = edge_threshold(kb, p.category)[1]
            assert p.edge_gap == round(limit + (BORDER_M if p.kind == "just_outside" else -BORDER_M), 4)
    free = [p for t in range(40)
            for p in choose_judgement_items(f"t{t}", "store_sharp_objects", set(), kb, on, hazard_free=True).near_misses]
    assert "just_inside" not in {p.kind for p in free}
    states = [choose_judgement_items(f"t{t}", "store_sharp_objects", set(), kb, on).state for t in range(20)]
    assert any(s is not None for s in states) and any(s is None for s in states)


def test_a_built_scene_carries_a_real_second_hazard_and_a_near_miss_no_class_fires_on(tmp_path):
    from anomalygen.detect.rules import candidates
    from anomalygen.runfolder import read_model
    from anomalygen.scene.build import build_scene
    from anomalygen.schema import HazardManifest, SceneGraph

    task = make_task("t-mix", "store_sharp_objects", "Table", "kitchen_knife", "counter_edge")
    settings = Settings(build={"clutter": 1, "near_misses": 1, "multi_hazard": 1.0})
    build_scene(task, seed=0, settings=settings, out_dir=tmp_path / "s")
    graph = read_model(tmp_path / "s" / "scene_graph.json", SceneGraph)
    items = choose_judgement_items(task.id, task.hazard_class, set(), load_kb(), settings)
    fired = {(c.hazard_class, c.object) for c in candidates(graph)}
    litter = next(o for o in graph.objects if o.category == items.second_hazard)
    assert litter.on_floor and (SECOND_HAZARD_CLASS, litter.name) in fired
    assert any(o.category == "TrashCan" for o in graph.objects)  # the robot has somewhere to put it
    (pick,) = items.near_misses
    decoys = [o for o in graph.objects if o.category == pick.category]
    assert decoys, "the near-miss found no room"
    truth = read_model(tmp_path / "s" / "truth.json", HazardManifest)
    for o in decoys:
        assert o.distance_to_edge is not None
        if pick.kind == "just_inside":  # a real hazard, listed as meant
            assert o.distance_to_edge <= 0.12 and any(h.object == o.name and h.source == "intended" for h in truth.hazards)
        else:
            assert not any(obj == o.name for _, obj in fired), o
            assert o.distance_to_edge > 0.12
            assert any(n.object == o.name and n.kind == ("object" if pick.kind == "far" else "borderline")
                       for n in truth.near_misses)
    assert any(h.object == litter.name and h.source == "intended" for h in truth.hazards)
