"""move_away_from_edge on scenes the scene stage built, with the real simulator: the knowledge-base
plan runs, and the referee judges the released, settled end state. The fragile object must end at
least the class's 0.15 m from every edge of the top it rests on, measured the referee's way."""

from __future__ import annotations

import pytest

from anomalygen.schema import SceneGraph
from support.kb_scenes import build_with_kb_plans, kb_task

NEAR_EDGE = 0.15  # m: move_fragile_from_edge's success rule (near_edge max_distance, negated)

TASKS = {
    # a vase at the edge of a table with room to spare: set back on its own table
    "table": kb_task("t-vase-edge", "move_fragile_from_edge", "Table", "vase", "table_edge", room="living_room"),
    # a vase at the edge of a shelf narrower than twice the margin (a table in the room): elsewhere
    "shelf": kb_task("t-vase-shelf", "move_fragile_from_edge", "Table", "vase", "shelf_edge", room="living_room"),
}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    return build_with_kb_plans(TASKS, tmp_path_factory.mktemp("edge_scenes"), clutter=0)


def _judged(built, key, tmp_path):
    """(object at fault, the referee's verdict, the graph it judged, the robot's SkillResult)."""
    from anomalygen.learn.execute import execute_plan
    from anomalygen.referee import judge
    from anomalygen.referee.settle import settled_graph
    from anomalygen.world.graph import load_scene
    from anomalygen.world.state import restore_state

    scene_dir, spec, plan = built[key]
    res = execute_plan(scene_dir, plan, seed=0, final_state_path=tmp_path / "final.npz")
    model, data, full = load_scene(scene_dir)
    restore_state(tmp_path / "final.npz", model, data)
    graph: SceneGraph = settled_graph(model, data, full)[0]
    return spec.bindings["$hazard"], judge(scene_dir, model, data), graph, res


def _support(graph: SceneGraph, obj: str) -> str | None:
    return next((r.object for r in graph.relations if r.subject == obj and r.predicate == "on"), None)


@pytest.mark.slow
@pytest.mark.parametrize("key", ["table", "shelf"])
def test_the_fragile_object_ends_back_from_every_edge_as_the_referee_measures(built, key, tmp_path):
    from anomalygen.world.graph import load_scene, scene_graph

    scene_dir = built[key][0]
    obj, verdict, graph, res = _judged(built, key, tmp_path)
    before = scene_graph(*load_scene(scene_dir)).get(obj)
    assert before.distance_to_edge is not None and before.distance_to_edge < NEAR_EDGE
    after = graph.get(obj)
    assert not after.on_floor and after.distance_to_edge is not None
    assert after.distance_to_edge >= NEAR_EDGE, (after.distance_to_edge, [s.detail for s in res.subtasks])
    (h,) = [h for h in verdict.hazards if h.object == obj]
    assert h.resolved and verdict.new_hazards == [], (h.detail, verdict.new_hazards)
    assert res.success  # the robot's own check agrees with the referee


@pytest.mark.slow
def test_a_shelf_too_narrow_for_the_margin_sends_the_object_to_another_top(built, tmp_path):
    from anomalygen.world.graph import load_scene, scene_graph

    scene_dir = built["shelf"][0]
    obj = built["shelf"][1].bindings["$hazard"]
    first = _support(scene_graph(*load_scene(scene_dir)), obj)
    _, verdict, graph, res = _judged(built, "shelf", tmp_path)
    assert first is not None and first.startswith("shelf")
    assert _support(graph, obj) not in (None, first)
    assert "no spot 0.15 m from the edges of" in res.subtasks[0].detail


@pytest.mark.slow
def test_the_support_to_set_back_on_is_where_the_object_rests_now_not_where_the_spec_put_it(built):
    """A second edge step after the object moved (the loop's recheck of a laptop carried from the
    sink to a table) must work on the table it is on now; it used to read the spec's first support."""
    from anomalygen.rng import item_rng
    from anomalygen.skills import geometry
    from anomalygen.skills.episode import Episode, EpisodeBudget, LearningSettings
    from anomalygen.skills.scripted import relocate
    from anomalygen.world.perception import load_perceived_scene

    scene_dir, spec, plan = built["shelf"]
    obj = spec.bindings["$hazard"]
    model, data, perceived = load_perceived_scene(scene_dir)
    ep = Episode(model, data, perceived, seed=0, rng=item_rng(0, "recheck"), plan=plan, budget=EpisodeBudget(),
                 learning=LearningSettings())
    first = geometry.surface_centre_of(ep, obj)
    assert first is not None and first.startswith("shelf")
    assert relocate.back_from_edge(ep, obj, first).success
    now = geometry.surface_centre_of(ep, obj)
    assert now not in (None, first) and next(o.support for o in ep.spec.objects if o.name == obj) == first


@pytest.mark.slow
def test_an_object_on_no_top_is_set_back_on_the_nearest_safe_one(built):
    """A vase knocked to the floor (no support to re-centre on: the skill used to fail, "stands on no
    support") is set on the nearest safe top, back from its edges."""
    from anomalygen.rng import item_rng
    from anomalygen.skills.episode import Episode, EpisodeBudget, LearningSettings
    from anomalygen.skills.scripted import relocate
    from anomalygen.world.perception import load_perceived_scene

    scene_dir, spec, plan = built["table"]
    obj = spec.bindings["$hazard"]
    model, data, perceived = load_perceived_scene(scene_dir)
    ep = Episode(model, data, perceived, seed=0, rng=item_rng(0, "floor"), plan=plan, budget=EpisodeBudget(),
                 learning=LearningSettings())
    out = relocate.back_from_edge(ep, obj, None)
    assert out.success and "was on the floor, no top to re-centre on" in out.detail, out.detail
    after = ep.graph().get(obj)
    assert not after.on_floor and after.distance_to_edge is not None and after.distance_to_edge >= NEAR_EDGE - 0.03


@pytest.mark.slow
def test_a_long_thing_on_a_crowded_table_is_set_down_crosswise_back_from_the_edges(tmp_path):
    """The seed-0 loop's t0046 at 182830c, built verbatim: a dumbbell at the edge of a table whose
    middle holds a box, a tissue box and a cup. Lengthwise the clearest spot is 0.13 m from an edge
    (the robot tried twice and the referee said 0.13 m); turned a quarter turn it is 0.16 m."""
    from pathlib import Path

    from anomalygen.skills.scripted import relocate
    from support.built_task import episode_on_built_task

    ep = episode_on_built_task(Path(__file__).parent / "fixtures" / "dumbbell_crowded_table.json", tmp_path / "scene")
    before = ep.graph().get("dumbbell_0")
    assert before.distance_to_edge is not None and before.distance_to_edge < NEAR_EDGE
    res = relocate.back_from_edge(ep, "dumbbell_0", "table_0")
    assert "crosswise" in res.detail, res.detail
    after = ep.graph().get("dumbbell_0")
    assert _support(ep.graph(), "dumbbell_0") == "table_0"
    assert after.distance_to_edge >= NEAR_EDGE, (after.distance_to_edge, res.detail)
