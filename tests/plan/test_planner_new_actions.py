"""The recipe actions push_to, close_lid, open_lid, take_out_of and place_on in both planners: the
knowledge planner turns them into the executor's primitives, opens a shut appliance around a take-out,
and the LLM planner's menu offers them and its checker accepts them on a scene that has the objects."""

from __future__ import annotations

from anomalygen.plan import llm_prompt as Prompt
from anomalygen.plan import plan_llm as P
from anomalygen.plan.planner import plan_from_kb, step_to_subtask
from anomalygen.schema import AssetRef, JointState, ObjectRole, PlacedObject, SceneSpec


def _obj(name, category, role, *, fixed=False, joints=()):
    return PlacedObject(name=name, asset=AssetRef(asset_id=f"test-{category}", category=category), role=role,
                        size=0.3, pos=[0.5, 0.0, 0.9], support="floor", fixed=fixed, joint_states=list(joints))


def microwave_scene() -> SceneSpec:
    door = JointState(name="microwave_0/door_hinge", label="door", value=0.0, range=(-2.0, 0.0), closed_value=0.0)
    return SceneSpec(scene_id="t-mw", task_id="t-mw", room="kitchen", seed=0, objects=[
        _obj("counter_0", "counter", ObjectRole.SUPPORT, fixed=True),
        _obj("microwave_0", "Microwave", ObjectRole.TARGET, joints=[door]),
        _obj("fork_0", "fork", ObjectRole.HAZARD),
        _obj("box_0", "Box", ObjectRole.AUXILIARY, joints=[
            JointState(name="box_0/lid_hinge", label="lid", value=1.0, range=(0.0, 2.0), closed_value=0.0)]),
        _obj("dumbbell_0", "dumbbell", ObjectRole.AUXILIARY),
    ], bindings={"$hazard": "fork_0", "$target": "microwave_0", "$support": "counter_0"})


def test_each_new_action_becomes_its_primitive():
    b = {"$hazard": "dumbbell_0", "$support": "table_0", "$target": "box_0", "$container": "microwave_0"}
    cases = {
        "push_to": ({"object": "$hazard", "support": "$support"}, "push_to", {"object": "dumbbell_0", "region": "table_0"}),
        "close_lid": ({"object": "$target"}, "close_lid", {"object": "box_0", "part": "lid|flap"}),
        "open_lid": ({"object": "$target"}, "open_lid", {"object": "box_0", "part": "lid|flap"}),
        "take_out_of": ({"object": "$hazard", "container": "$container"}, "take_out_of",
                        {"object": "dumbbell_0", "region": "microwave_0"}),
        "place_on": ({"object": "$hazard", "support": "$support"}, "move_to",
                     {"object": "dumbbell_0", "region": "table_0", "release": True}),
    }
    for action, (args, prim, params) in cases.items():
        st = step_to_subtask(0, action, args, b, None, [])
        assert (st.primitive, st.params) == (prim, params), action
        assert st.reward is not None and st.reward.terms


def test_a_take_out_of_a_shut_microwave_is_wrapped_in_opening_and_closing_it():
    spec = microwave_scene()
    plan = plan_from_kb("t-mw", "remove_item_from_appliance", dict(spec.bindings), spec=spec)
    assert [st.id for st in plan.subtasks] == ["s0_open_container", "s1_take_out_of", "s2_place_on", "s9_close_container"]
    take = plan.subtasks[1]
    # its own check is only 'no longer inside' (the item is still held afterwards, so it rests on nothing)
    assert [(c.name, c.negate) for c in take.success.predicates] == [("inside", True)]
    assert plan.subtasks[3].params["object"] == "microwave_0"


def test_the_llm_menu_offers_the_new_primitives_and_the_checker_accepts_them():
    assert {"push_to", "take_out_of", "close_lid", "open_lid", "place_on"} <= set(Prompt.PRIMITIVES)
    spec = microwave_scene()
    scene = P.PlanScene(spec, dict(spec.bindings))
    reply = {
        "subtasks": [
            {"id": "s1_open", "description": "open the microwave", "method": "primitive", "primitive": "pull",
             "params": {"object": "$target", "part": "door"}},
            {"id": "s2_take", "description": "take the fork out", "method": "primitive", "primitive": "take_out_of",
             "params": {"object": "$hazard", "region": "$target"}},
            {"id": "s3_put", "description": "lay it on the counter", "method": "primitive", "primitive": "place_on",
             "params": {"object": "fork_0", "region": "$support"}},
            {"id": "s4_push", "description": "push the dumbbell aside", "method": "primitive", "primitive": "push_to",
             "params": {"object": "dumbbell_0", "region": "counter_0"}},
            {"id": "s5_lid", "description": "shut the box", "method": "primitive", "primitive": "close_lid",
             "params": {"object": "box_0"}},
        ],
        "success": [{"name": "inside", "args": {"object": "$hazard", "container": "$target"}, "negate": True}],
    }
    assert P.check_reply(P.TaskPlan.model_validate(reply), scene) == []
    bad = dict(reply, subtasks=[dict(reply["subtasks"][1], params={"object": "$hazard"})])
    assert any("take_out_of needs params.region" in p for p in P.check_reply(P.TaskPlan.model_validate(bad), scene))
