"""Oracle plans on built scenes for the containers and objects that used to defeat the primitives
(issue 17): a safe or medicine cabinet behind a low door, a long cable lying across a walkway.
Each test asserts where the object physically ends up, not just that the plan ran."""

from __future__ import annotations

import pytest

from support.kb_scenes import build_with_kb_plans


def make_task(task_id, hazard_class, target, hazard, placement, *, room="kitchen", container=None):
    from anomalygen.schema import TaskProposal

    return TaskProposal(
        id=task_id, name=f"task {task_id}", explanation="test", description=f"A {hazard} at {placement}.",
        category="household_hazard", hazard_class=hazard_class, target_asset=target,
        scenario=dict(hazard_object=hazard, room=room, placement=placement, container=container, co_objects=[]),
        articulations=[], provenance=dict(engine="knowledge", mode="brainstorm"))


TASKS = {
    "safe": make_task("t-safe", "secure_medications", "Safe", "pill_bottle", "low_table", container="Safe"),
    "cabinet": make_task("t-medcab", "secure_medications", "Bottle", "blister_pack", "table_edge",
                         room="living_room", container="medicine_cabinet"),
    # the benchmark's lighter-into-a-safe task: a loose safe tipped onto its back under the arm
    "lighter": make_task("t-lighter-safe", "keep_fire_starters_from_children", "Safe", "Lighter", "table",
                         room="bedroom", container="Safe"),
    "cable": make_task("t-cable", "clear_cable_from_walkway", "Laptop", "power_cable", "walkway", room="office"),
}


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    return build_with_kb_plans(TASKS, tmp_path_factory.mktemp("access_scenes"), clutter=1)


def _final_graph(tmp_path, key, built):
    from anomalygen.learn.execute import execute_plan
    from anomalygen.runfolder import read_model
    from anomalygen.schema import SceneGraph

    scene_dir, spec, plan = built[key]
    res = execute_plan(scene_dir, plan, seed=0, final_graph_path=tmp_path / "graph.json")
    return spec, plan, res, read_model(tmp_path / "graph.json", SceneGraph)


def _door_value(graph, container):
    obj = next(o for o in graph.objects if o.name == container)
    return [j.value for j in obj.joints if j.label == "door"]


# The safe's door: on the 2026-12-07 machine the close step leaves it at -1.34 then -0.43 rad (two
# attempts), the same at 1e3de4c where CI had passed on another machine; the physics is deterministic
# on one machine (a rerun repeats every control step), so it is the float arithmetic of another CPU
# that tips this contact-rich close. Not strict: it passes where the close lands.
SAFE_CLOSE_BRITTLE = pytest.mark.xfail(strict=False, reason="the safe-door close is brittle across CPUs "
                                       "(docs/benchmarks.md, issue 37)")


@pytest.mark.slow
@pytest.mark.parametrize("key", [pytest.param("safe", marks=SAFE_CLOSE_BRITTLE), "cabinet"])
def test_object_goes_behind_a_low_door_that_is_shut_again(built, tmp_path, key):
    """The container has only a door (no lid, no drawer): the plan opens it, the object goes in
    (sideways, ahead of a horizontal cup, when the compartment is too low for a face-down hand), and
    the door ends shut with the object inside."""
    spec, plan, res, graph = _final_graph(tmp_path, key, built)
    hazard, container = spec.bindings["$hazard"], spec.bindings["$container"]
    assert [s.id for s in plan.subtasks][0] == "s0_open_container"
    assert res.subtasks[0].success and "opened" in res.subtasks[0].detail, res.subtasks[0].detail
    assert any(r.subject == hazard and r.predicate == "inside" and r.object == container
               for r in graph.relations), [s.detail for s in res.subtasks]
    assert all(abs(v) < 0.1 for v in _door_value(graph, container))  # shut again
    assert res.success


@pytest.mark.slow
def test_cable_across_a_walkway_is_lifted_off_the_floor(built, tmp_path):
    """A 1-2 m cable is a loose body (it used to be welded as furniture, so suction never held it):
    it is picked and ends off the floor, on the support the plan names."""
    spec, plan, res, graph = _final_graph(tmp_path, "cable", built)
    hazard = spec.bindings["$hazard"]
    assert res.subtasks[0].success, res.subtasks[0].detail
    obj = next(o for o in graph.objects if o.name == hazard)
    assert not obj.on_floor
    assert res.success, [s.detail for s in res.subtasks]


def test_cables_are_loose_whatever_their_length():
    from anomalygen.scene.asset_choice import FIXED_SIZE, Chosen
    from anomalygen.schema import ObjectRole

    class _Big:
        size = 2 * FIXED_SIZE

    assert not Chosen("power_cable_0", "power_cable", ObjectRole.HAZARD, _Big()).fixed
    assert Chosen("table_0", "lamp", ObjectRole.HAZARD, _Big()).fixed


def test_a_safe_is_bolted_down_whatever_its_size():
    from anomalygen.scene.asset_choice import FIXED_SIZE, Chosen
    from anomalygen.schema import ObjectRole

    class _Small:
        size = FIXED_SIZE / 2

    assert Chosen("safe_0", "Safe", ObjectRole.CONTAINER, _Small()).fixed


@pytest.mark.slow
def test_a_lighter_locked_in_a_safe_is_judged_resolved_by_the_referee(built, tmp_path):
    """Open the safe, put the lighter in, push the door shut: the safe does not budge, and the referee
    (released, settled, judged against the hidden truth) finds the child hazard resolved."""
    import numpy as np

    from anomalygen.learn.execute import execute_plan
    from anomalygen.referee import judge
    from anomalygen.world.graph import load_scene
    from anomalygen.world.state import restore_state

    scene_dir, spec, plan = built["lighter"]
    container = spec.bindings["$container"]
    model, data, _ = load_scene(scene_dir)
    before = data.body(container).xpos.copy()
    res = execute_plan(scene_dir, plan, seed=0, final_state_path=tmp_path / "final.npz")
    restore_state(tmp_path / "final.npz", model, data)
    assert np.linalg.norm(data.body(container).xpos - before) < 1e-3
    assert abs(float(data.joint(f"{container}/door_hinge").qpos[0])) < 0.1, [s.detail for s in res.subtasks]
    verdict = judge(scene_dir, model, data)
    assert verdict.resolved, verdict
