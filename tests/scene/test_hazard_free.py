"""Hazard-free scenes: the task's object is built in its safe state and the answer key says so."""

from __future__ import annotations

from anomalygen.config import Settings
from anomalygen.runfolder import read_model
from anomalygen.schema import HazardManifest, SceneGraph, SceneSpec

from .conftest import TASKS

SAFE = Settings(build={"clutter": 1, "near_misses": 0, "multi_hazard": 0.0})


def _build(key, tmp_path):
    from anomalygen.scene.build import build_scene

    out = tmp_path / key
    build_scene(TASKS[key], seed=0, settings=SAFE, out_dir=out, hazard_free=True)
    return (read_model(out / "scene.json", SceneSpec), read_model(out / "scene_graph.json", SceneGraph),
            read_model(out / "truth.json", HazardManifest))


def test_a_hazard_free_fridge_scene_has_its_door_shut_and_an_empty_answer_key(tmp_path):
    spec, graph, truth = _build("fridge", tmp_path)
    fridge = next(o for o in graph.objects if o.category == "Refrigerator")
    assert all(j.open_fraction < 0.05 for j in fridge.joints if j.label == "door")
    assert truth.hazards == [] and spec.bindings == {}
    assert any(c.name == "hazard_free" and c.passed for c in spec.validation.checks)


def test_a_hazard_free_pill_scene_shuts_the_pills_away(tmp_path):
    from anomalygen.knowledge import load_kb
    from anomalygen.truth.manifest import class_matches

    spec, graph, truth = _build("floor", tmp_path)  # a button battery, normally on the floor
    battery = next(o for o in graph.objects if o.category == "button_battery")
    assert not battery.on_floor and not battery.child_reachable
    assert any(r.subject == battery.name and r.predicate == "inside" for r in graph.relations)
    assert not any(obj == battery.name for _, obj, _ in class_matches(graph, load_kb()))
    assert truth.hazards == [] and battery.name in {n.object for n in truth.near_misses}


def test_the_share_of_hazard_free_scenes_follows_the_setting():
    from anomalygen.scene.mix import is_hazard_free

    ids = [f"t{i:04d}" for i in range(400)]
    share = sum(is_hazard_free(t, Settings()) for t in ids) / len(ids)
    assert 0.10 <= share <= 0.20  # default 0.15
    assert not any(is_hazard_free(t, Settings(build={"hazard_free": 0.0})) for t in ids)
    assert [is_hazard_free(t, Settings()) for t in ids] == [is_hazard_free(t, Settings()) for t in ids]


def test_a_hazard_free_high_shelf_scene_has_the_hammer_down_on_the_table(tmp_path):
    """The safe version of 'a hammer on a high shelf' is where the fix leaves it: on the table (the
    seed-19 demo's t0006 failed its build with the hammer put back on the shelf)."""
    from pathlib import Path

    from anomalygen.scene.build import build_scene
    from anomalygen.schema import TaskProposal

    task = TaskProposal.model_validate_json((Path(__file__).parent / "fixtures" / "hammer_on_high_shelf.json").read_text())
    out = tmp_path / "hammer"
    build_scene(task, seed=19, settings=SAFE, out_dir=out, hazard_free=True)
    graph = read_model(out / "scene_graph.json", SceneGraph)
    hammer = next(o for o in graph.objects if o.category == "hammer")
    on = {r.object for r in graph.relations if r.subject == hammer.name and r.predicate == "on"}
    assert any(n.startswith("table") for n in on), on
    assert hammer.position[2] < 1.1
    assert read_model(out / "truth.json", HazardManifest).hazards == []


def test_a_task_object_that_could_fire_the_class_is_made_safe_with_the_hazard(tmp_path):
    """A loose task object of a kind the class is about goes where the made-safe hazard went: the
    target lighter shut in the safe beside the matches, the target camera on the table beside the bowl
    (the seed-0 loop's t0109 and t0076 failed their hazard-free builds with them left on the floor)."""
    from pathlib import Path

    from anomalygen.scene.build import build_scene
    from anomalygen.schema import TaskProposal

    for fixture, hazard, extra in (("matches_on_floor_lighter_target", "matches", "Lighter"),
                                   ("bowl_on_floor_camera_target", "bowl", "Camera")):
        task = TaskProposal.model_validate_json((Path(__file__).parent / "fixtures" / f"{fixture}.json").read_text())
        out = tmp_path / fixture
        build_scene(task, seed=0, settings=SAFE, out_dir=out, hazard_free=True)
        graph = read_model(out / "scene_graph.json", SceneGraph)
        by_cat = {o.category: o for o in graph.objects}
        assert not by_cat[hazard].on_floor and not by_cat[extra].on_floor, fixture
        if extra == "Lighter":
            assert not by_cat[extra].child_reachable
            assert {r.object for r in graph.relations if r.subject == by_cat[extra].name and r.predicate == "inside"} \
                == {r.object for r in graph.relations if r.subject == by_cat[hazard].name and r.predicate == "inside"} != set()
        assert read_model(out / "truth.json", HazardManifest).hazards == [], fixture


def test_a_hazard_too_tall_for_its_container_is_made_safe_beside_the_furniture(tmp_path):
    """A backpack (0.4 m and more, standing) does not stand in a cabinet's compartment; its safe
    state is then out of the walkway, not a failed build (the seed-0 loop's t0092 at bf44e13 failed,
    "backpack_0 does not fit inside storagefurniture_0"). The task is that loop's, verbatim."""
    from pathlib import Path

    from anomalygen.scene.build import build_scene
    from anomalygen.schema import TaskProposal

    task = TaskProposal.model_validate_json(
        (Path(__file__).parent / "fixtures" / "backpack_in_walkway_cabinet_container.json").read_text())
    out = tmp_path / "backpack"
    build_scene(task, seed=0, settings=SAFE, out_dir=out, hazard_free=True)
    graph = read_model(out / "scene_graph.json", SceneGraph)
    backpack = next(o for o in graph.objects if o.category == "backpack")
    assert not any(r.subject == backpack.name and r.predicate in ("inside", "in_walkway") for r in graph.relations)
    assert read_model(out / "truth.json", HazardManifest).hazards == []
