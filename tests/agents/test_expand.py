"""A call becomes sub-tasks through the planner's own machinery: a shut container is opened and shut
around a place, one named knob is one sub-task, fix is the knowledge base's recipe, and each call
checks what it means."""

from __future__ import annotations

import pytest

from anomalygen.agents.expand import plan_for_call
from anomalygen.agents.observe import objects_of
from anomalygen.agents.vocabulary import CallError, SceneView, parse_call, validate_call
from anomalygen.knowledge import load_kb
from anomalygen.world.perception import load_perceived_spec, load_scene_graph


@pytest.fixture(scope="module")
def scene(skill_scenes):
    _, folder = skill_scenes["pan"]
    return load_scene_graph(folder), load_perceived_spec(folder), load_kb()


def plan(text, scene):
    graph, spec, kb = scene
    call = validate_call(parse_call(text), SceneView.from_objects(objects_of(graph, spec)), kb)
    return plan_for_call(call, graph, spec, kb, "t-test")


def _steps(p):
    return [(st.id, st.primitive) for st in p.subtasks]


def test_a_place_into_a_shut_container_opens_it_first_and_shuts_it_after(scene):
    p = plan("pick_place(banana_0, kitchenpot_0)", scene)
    assert _steps(p) == [("s0_open_container", "pull"), ("s1_pick", "grasp"), ("s2_place_inside", "move_to"),
                         ("s9_close_container", "push")]
    assert [c.name for c in p.subtasks[2].success.predicates] == ["inside"]
    assert p.bindings == {"$hazard": "banana_0", "$container": "kitchenpot_0"} and p.source == "detected"


def test_one_named_part_is_one_sub_task_and_switching_off_is_learned(scene):
    p = plan("switch_off(hair_dryer_0, switch_press)", scene)
    (st,) = p.subtasks
    assert st.params["joint"] == "hair_dryer_0/switch_press" and st.method == "sac" and st.primitive == "push"
    whole = plan("switch_off(hair_dryer_0)", scene)
    assert [c.name for c in whole.success.predicates] == ["is_on"] and whole.success.predicates[0].negate


def test_a_lid_is_closed_by_the_lid_skill_and_a_turn_checks_the_handle(scene):
    assert _steps(plan("close(kitchenpot_0, lid)", scene)) == [("s1_close_lid", "close_lid")]
    turn = plan("turn_inward(kitchenpot_0)", scene)
    assert _steps(turn) == [("s1_rotate_inward", "rotate_inward")]
    (check,) = turn.subtasks[0].success.predicates
    assert (check.name, check.negate, check.args["state"]) == ("has_state", True, "handle_out")


def test_fix_is_the_knowledge_bases_recipe_with_the_roles_the_planner_binds(scene):
    from anomalygen.plan.bind import bind_fix
    from anomalygen.plan.planner import plan_from_kb

    graph, spec, kb = scene
    hc = kb.hazard_classes["turn_pan_handle_inward"]
    expected = plan_from_kb("t-test", hc.id, bind_fix(hc, "kitchenpot_0", graph, kb), spec=spec, source="detected")
    assert plan("fix(kitchenpot_0, turn_pan_handle_inward)", scene) == expected


def test_a_fix_with_no_skill_yet_is_refused_with_the_planners_reason(scene):
    with pytest.raises(CallError, match="no skill for stand_upright yet"):
        plan("fix(hair_dryer_0, stand_iron_upright)", scene)
