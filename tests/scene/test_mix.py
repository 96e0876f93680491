"""Near-miss distractors and the second hazard: chosen from the scene's own generator, real in the built scene."""

from __future__ import annotations

import pytest

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



def test_a_users_own_line_is_never_hazard_free_nor_given_a_second_hazard():
    from anomalygen.scene.mix import is_hazard_free

    kb = load_kb()
    always = Settings(build={"near_misses": 1, "multi_hazard": 1.0, "hazard_free": 1.0})
    assert is_hazard_free("t1", always) and not is_hazard_free("t1", always, source="user_text")
    items = choose_judgement_items("t1", "store_sharp_objects", set(), kb, always, source="user_text")
    assert items.second_hazard is None and items.bin is None and len(items.near_misses) == 1


def test_near_placements_build_the_composed_hazard_and_bind_its_other_object(tmp_path):
    """'near:<name>': a cleaner on the bread's counter within reach of it, and a candle's flame read
    from its control; the composed class's other variable is bound in the scene's bindings."""
    from anomalygen.knowledge.predicates import match_class
    from anomalygen.runfolder import read_model
    from anomalygen.scene.build import build_scene
    from anomalygen.schema import SceneGraph

    settings = Settings(build={"clutter": 0, "near_misses": 0, "multi_hazard": 0.0, "hazard_free": 0.0})
    task = make_task("t-near", "separate_chemical_from_food", "StorageFurniture", "cleaning_spray", "near:bread_loaf",
                     co=["bread_loaf"])
    spec = build_scene(task, seed=0, settings=settings, out_dir=tmp_path / "s")
    graph = read_model(tmp_path / "s" / "scene_graph.json", SceneGraph)
    hc = load_kb().hazard_classes["separate_chemical_from_food"]
    food = spec.bindings["$food"]
    assert graph.get(food).category == "bread_loaf"
    assert [m.bindings for m in match_class(hc, graph, fixed={"$hazard": spec.bindings["$hazard"]})] == [
        {"$hazard": spec.bindings["$hazard"], "$food": food}]
    candle = make_task("t-candle", "move_hot_item_from_edge", "Table", "candle", "table_edge")
    build_scene(candle, seed=0, settings=settings, out_dir=tmp_path / "c")
    snuffed = read_model(tmp_path / "c" / "scene_graph.json", SceneGraph)
    # a candle's flame is its snuffer control: off unless the class asks for it lit (is_on / has_state lit)
    assert next(o for o in snuffed.objects if o.category == "candle").states == ["off"]


def test_the_bin_added_for_the_second_hazard_is_the_kind_the_planner_looks_for():
    """One rule: the builder adds a bin unless the scene holds a kind ``containers_for`` (the planner's
    choice for that very object) names. Litter goes in a bin, never a bucket (issue 39: a reader took
    'drop it into the bucket' for a slip), so a scene with only a bucket is given a trash can and a
    scene with a trash can is given none."""
    kb = load_kb()
    hc = kb.hazard_classes[SECOND_HAZARD_CLASS]
    on = Settings(build={"near_misses": 0, "multi_hazard": 1.0})
    assert hc.default_containers == ["TrashCan"]
    seen = {}
    for present in ({"Bucket"}, {"TrashCan"}):
        for t in range(60):
            items = choose_judgement_items(f"t{t}", "store_sharp_objects", present, kb, on)
            if items.second_hazard is None:
                continue
            wanted = kb.containers_for(hc, items.second_hazard)
            assert items.bin_kinds == wanted == ["TrashCan"]
            seen.setdefault(frozenset(present), set()).add(items.bin)
    assert seen == {frozenset({"Bucket"}): {"TrashCan"}, frozenset({"TrashCan"}): {None}}


@pytest.mark.slow
def test_a_plastic_bag_second_hazard_comes_with_a_bin_it_goes_into_in_the_simulator(tmp_path):
    """A flat plastic bag (0.3 m at its smallest) was paired with a bin whose mouth was 0.15 m: the
    robot lifted it and lowered it onto the rim, twice. The builder now draws the bin (or the bag) so
    the bag fits, and the robot's own plan puts it in: inside the bin in the settled simulator."""
    from anomalygen.learn.execute import execute_plan
    from anomalygen.plan.bind import bind_fix
    from anomalygen.plan.planner import plan_from_kb
    from anomalygen.runfolder import read_model
    from anomalygen.scene.asset_choice import container_room
    from anomalygen.scene.build import build_scene
    from anomalygen.schema import SceneGraph

    kb = load_kb()
    settings = Settings(build={"clutter": 0, "near_misses": 0, "multi_hazard": 1.0, "hazard_free": 0.0})
    task = make_task("t-bag2", "store_sharp_objects", "Table", "kitchen_knife", "counter_edge")
    assert choose_judgement_items(task.id, task.hazard_class, set(), kb, settings).second_hazard == "plastic_bag"
    spec = build_scene(task, seed=0, settings=settings, out_dir=tmp_path / "s")
    bag = next(o for o in spec.objects if o.asset.category == "plastic_bag")
    bins = [o for o in spec.objects if o.asset.category == "TrashCan"]
    assert bins and bag.size <= max(container_room(o) for o in bins)  # its declared cavities
    graph = read_model(tmp_path / "s" / "scene_graph.json", SceneGraph)
    hc = kb.hazard_classes[SECOND_HAZARD_CLASS]
    bindings = bind_fix(hc, bag.name, graph, kb)
    assert bindings["$container"] in {o.name for o in bins}
    plan = plan_from_kb(task.id, hc.id, bindings, spec=spec)
    result = execute_plan(tmp_path / "s", plan, seed=0)
    inside = [p for p in result.final_predicates if p.call.name == "inside"]
    assert inside and all(p.holds for p in inside), [p.explanation for p in inside]
