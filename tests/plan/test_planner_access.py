"""Access steps and SAC hand-over in knowledge-base plans, on scene specs written here (no MuJoCo).

A container that the scene shows shut must be opened before the pick and shut again after the place;
one that stands open needs neither. Recipe actions listed in ``sac_actions`` go to SAC with the same
reward spec the primitive step carries.
"""

from __future__ import annotations

import pytest

from anomalygen.plan.planner import access_steps, closed_closures, plan_from_kb
from anomalygen.schema import (
    AssetRef,
    Engine,
    HazardCategory,
    JointState,
    ObjectRole,
    PlacedObject,
    Plan,
    Provenance,
    Scenario,
    SceneSpec,
    SkillMethod,
    TaskProposal,
)

LID_RANGE = (-1.9, 0.0)


def _obj(name: str, category: str, role: ObjectRole, joints=(), pos=(1.0, 0.0, 0.0)) -> PlacedObject:
    return PlacedObject(name=name, asset=AssetRef(asset_id=f"{category}-0", category=category), role=role,
                        size=0.4, pos=list(pos), joint_states=list(joints))


def _lid(value: float) -> JointState:
    return JointState(name="storage_box_0/lid_hinge", label="lid", type="hinge", value=value, range=LID_RANGE,
                      closed_value=0.0)


def _spec(container_joints, *, extra=()) -> SceneSpec:
    objects = [_obj("knife_0", "kitchen_knife", ObjectRole.HAZARD, pos=(0.8, 0.2, 0.75)),
               _obj("storage_box_0", "storage_box", ObjectRole.CONTAINER, container_joints), *extra]
    return SceneSpec(scene_id="s", task_id="t", room="kitchen", seed=0, objects=objects,
                     bindings={"$hazard": "knife_0", "$container": "storage_box_0"})


def _store_plan(spec: SceneSpec, **kw) -> Plan:
    return plan_from_kb("t", "store_sharp_objects", dict(spec.bindings), spec=spec, **kw)


def test_shut_lid_puts_open_and_close_steps_around_pick_and_place():
    plan = _store_plan(_spec([_lid(0.0)]))
    assert [s.id for s in plan.subtasks] == ["s0_open_container", "s1_pick", "s2_place_inside", "s9_close_container"]
    opened, pick, place, shut = plan.subtasks
    assert (opened.primitive, shut.primitive) == ("pull", "push")
    for st in (opened, shut):
        assert st.method == SkillMethod.PRIMITIVE
        assert st.params == {"object": "storage_box_0", "part": "lid", "access": True}
        assert st.reward is not None and st.reward.terms
    assert not opened.success.predicates  # opening is judged by the place that follows
    (closed,) = shut.success.predicates
    assert closed.name == "joint_closed" and not closed.negate
    assert closed.args == {"object": "storage_box_0", "label": "lid", "max_fraction": 0.1}
    # the pick and place between them are the recipe's, bound to the scene instances
    assert pick.params["object"] == "knife_0" and place.params["region"] == "storage_box_0"
    assert [p.name for p in place.success.predicates] == ["inside"]
    # the task's own success stays the class's: the object inside the container
    assert [p.name for p in plan.success.predicates] == ["inside"]
    assert Plan.model_validate_json(plan.model_dump_json()) == plan


@pytest.mark.parametrize("value", [-1.5, -0.4])
def test_open_lid_needs_no_access_steps(value):
    """An open lid (79 % and 21 % of its swing) leaves the plan as the bare recipe."""
    spec = _spec([_lid(value)])
    assert closed_closures(spec, "storage_box_0") == []
    plan = _store_plan(spec)
    assert [s.id for s in plan.subtasks] == ["s1_pick", "s2_place_inside"]
    assert not any(s.params.get("access") for s in plan.subtasks)


def test_nearly_shut_lid_counts_as_shut():
    """Under a tenth of the swing open (0.15 of 1.9 rad) nothing fits through: open it first."""
    spec = _spec([_lid(-0.15)])
    assert closed_closures(spec, "storage_box_0") == ["lid"]
    assert _store_plan(spec).subtasks[0].id == "s0_open_container"


def test_drawers_and_doors_are_named_together_in_the_access_steps():
    drawer = JointState(name="storage_box_0/drawer_0_0_slide", label="drawer", type="slide", value=0.0,
                        range=(0.0, 0.35), closed_value=0.0)
    door = JointState(name="storage_box_0/door_1_0_hinge", label="door", value=0.0, range=(-1.9, 0.0),
                      closed_value=0.0)
    knob = JointState(name="storage_box_0/knob_0_joint", label="knob", value=0.0, range=(0.0, 4.7),
                      closed_value=0.0)
    spec = _spec([door, knob, drawer])
    assert closed_closures(spec, "storage_box_0") == ["drawer", "door"]  # knobs do not shut anything
    plan = _store_plan(spec)
    assert plan.subtasks[0].params["part"] == "drawer|door"
    assert plan.subtasks[-1].success.predicates[0].args["label"] == "drawer|door"


def test_no_scene_or_other_instance_means_no_access_steps():
    assert closed_closures(None, "storage_box_0") == []
    spec = _spec([_lid(0.0)])
    assert closed_closures(spec, "knife_0") == []
    plan = plan_from_kb("t", "store_sharp_objects", dict(spec.bindings))  # no spec: nothing known to be shut
    assert [s.id for s in plan.subtasks] == ["s1_pick", "s2_place_inside"]


def test_access_steps_describe_the_container_they_act_on():
    opened, shut = access_steps("bin_3", ["lid", "flap"])
    assert opened.params["object"] == shut.params["object"] == "bin_3"
    assert opened.params["part"] == "lid|flap" and "bin_3" in opened.description and "bin_3" in shut.description


def _oven_spec(door_value: float = 1.2) -> SceneSpec:
    door = JointState(name="oven_0/door_hinge", label="door", value=door_value, range=(0.0, 1.55), closed_value=0.0)
    return SceneSpec(scene_id="s", task_id="t", room="kitchen", seed=0,
                     objects=[_obj("oven_0", "Oven", ObjectRole.HAZARD, [door])],
                     bindings={"$hazard": "oven_0", "$target": "oven_0"})


def test_sac_actions_hand_the_close_step_to_sac_with_its_reward():
    spec = _oven_spec()
    base = plan_from_kb("t", "close_oven_or_microwave", dict(spec.bindings), spec=spec)
    sac = plan_from_kb("t", "close_oven_or_microwave", dict(spec.bindings), spec=spec, sac_actions=["close_joint"])
    assert [s.method for s in base.subtasks] == [SkillMethod.PRIMITIVE]
    assert [s.method for s in sac.subtasks] == [SkillMethod.SAC]
    (b,), (s,) = base.subtasks, sac.subtasks
    # everything but the method is kept: the reward SAC learns from, the params, the success check
    assert s.reward == b.reward and s.params == b.params and s.success == b.success and s.id == b.id
    joint_terms = [t for t in s.reward.terms if t.kind == "joint"]
    assert len(joint_terms) == 1 and joint_terms[0].joint == "oven_0/door_hinge" and joint_terms[0].target == 0.0
    # an action the recipe does not use changes nothing
    other = plan_from_kb("t", "close_oven_or_microwave", dict(spec.bindings), spec=spec, sac_actions=["pick"])
    assert other == base


def test_sac_actions_leave_the_access_steps_scripted():
    spec = _spec([_lid(0.0)])
    plan = _store_plan(spec, sac_actions=("pick",))
    methods = {s.id: s.method for s in plan.subtasks}
    assert methods == {"s0_open_container": SkillMethod.PRIMITIVE, "s1_pick": SkillMethod.SAC,
                       "s2_place_inside": SkillMethod.PRIMITIVE, "s9_close_container": SkillMethod.PRIMITIVE}
    assert plan.subtasks[1].reward == _store_plan(spec).subtasks[1].reward


def _task(tid: str, hazard_class: str, target: str) -> TaskProposal:
    return TaskProposal(id=tid, name="n", explanation="e", description="d", category=HazardCategory.HOUSEHOLD_HAZARD,
                        hazard_class=hazard_class, target_asset=target,
                        scenario=Scenario(hazard_object=target, room="kitchen", placement="floor"),
                        provenance=Provenance(engine=Engine.KNOWLEDGE, mode="plain"))


def test_plan_stage_honours_settings_sac_actions(tmp_path):
    from anomalygen.config import Settings
    from anomalygen.plan.stage import run_stage
    from anomalygen.runfolder import RunFolder, read_model, write_jsonl, write_model

    run = RunFolder.create(tmp_path / "r")
    write_jsonl(run.tasks_path, [_task("oven", "close_oven_or_microwave", "Oven"),
                                 _task("box", "store_sharp_objects", "kitchen_knife")])
    # built scenes the plan stage reads: an open oven door, a shut storage box
    run.scene_dir("oven").mkdir(parents=True)
    write_model(run.scene_dir("oven") / "scene.json", _oven_spec())
    run.scene_dir("box").mkdir(parents=True)
    write_model(run.scene_dir("box") / "scene.json", _spec([_lid(0.0)]))

    settings = Settings(quiet=True)
    settings.plan.source = "ground_truth"  # the oracle: these scenes have no detections
    settings.plan.sac_actions = ["close_joint", "place_inside"]
    summary = run_stage(run, settings)
    assert summary.done == 2 and summary.failed == 0, summary.errors

    oven = read_model(run.plan_path("oven"), Plan)
    (step,) = oven.subtasks
    assert step.method == SkillMethod.SAC and step.params["joint"] == "oven_0/door_hinge"
    assert any(t.kind == "joint" and t.joint == "oven_0/door_hinge" for t in step.reward.terms)

    box = read_model(run.plan_path("box"), Plan)
    assert {s.id: s.method for s in box.subtasks} == {
        "s0_open_container": SkillMethod.PRIMITIVE, "s1_pick": SkillMethod.PRIMITIVE,
        "s2_place_inside": SkillMethod.SAC, "s9_close_container": SkillMethod.PRIMITIVE}

    # the default settings keep every step scripted
    again = run_stage(run, Settings(quiet=True, plan={"source": "ground_truth"}), force=True)
    assert again.done == 2
    assert all(s.method == SkillMethod.PRIMITIVE for s in read_model(run.plan_path("oven"), Plan).subtasks)
    assert all(s.method == SkillMethod.PRIMITIVE for s in read_model(run.plan_path("box"), Plan).subtasks)


def _fridge_spec(*, door: float, inside: str | None = "refrigerator_0", fridge_joints=True) -> SceneSpec:
    joints = [JointState(name="refrigerator_0/door_hinge", label="door", type="hinge", value=door, range=(0.0, 1.9),
                         closed_value=0.0),
              JointState(name="refrigerator_0/freezer_slide", label="drawer", type="slide", value=0.0,
                         range=(0.0, 0.5), closed_value=0.0)] if fridge_joints else []
    milk = _obj("spoiled_milk_carton_0", "spoiled_milk_carton", ObjectRole.HAZARD, pos=(1.8, 0.3, 0.5))
    milk = milk.model_copy(update={"inside": inside, "support": inside or "floor"})
    objects = [milk, _obj("refrigerator_0", "Refrigerator", ObjectRole.AUXILIARY, joints),
               _obj("trashcan_0", "TrashCan", ObjectRole.CONTAINER, [_lid(0.0)])]
    return SceneSpec(scene_id="s", task_id="t", room="kitchen", seed=0, objects=objects,
                     bindings={"$hazard": "spoiled_milk_carton_0", "$container": "trashcan_0"})


@pytest.mark.parametrize("door", [0.0, 1.3])
def test_food_in_a_fridge_is_taken_out_through_the_door_in_front_of_it(door):
    """Sour milk on a fridge shelf: picked from above the cup meets the fridge's top, so it comes out
    through the opening; the part in front of it is opened first (whether the scene shows it open
    or shut, the executor finds which one holds the carton) and every fridge door is shut at the end."""
    spec = _fridge_spec(door=door)
    plan = plan_from_kb("t", "dispose_spoiled_food", dict(spec.bindings), spec=spec)
    assert [s.id for s in plan.subtasks] == ["s0_open_container", "s0_open_source", "s1_take_out_of",
                                             "s2_place_inside", "s9_close_container", "s9_close_source"]
    opened, take, shut = plan.subtasks[1], plan.subtasks[2], plan.subtasks[5]
    assert opened.params == shut.params == {"object": "refrigerator_0", "part": "drawer|door", "access": True,
                                            "contents": "spoiled_milk_carton_0"}
    assert (opened.primitive, take.primitive, shut.primitive) == ("pull", "take_out_of", "push")
    assert take.params == {"object": "spoiled_milk_carton_0", "region": "refrigerator_0"}
    [out] = take.success.predicates
    assert out.name == "inside" and out.negate and out.args["container"] == "refrigerator_0"


@pytest.mark.parametrize("inside,fridge_joints", [(None, True), ("refrigerator_0", False)])
def test_food_on_a_table_or_in_an_open_box_is_still_picked(inside, fridge_joints):
    spec = _fridge_spec(door=0.0, inside=inside, fridge_joints=fridge_joints)
    plan = plan_from_kb("t", "dispose_spoiled_food", dict(spec.bindings), spec=spec)
    assert [s.id for s in plan.subtasks] == ["s0_open_container", "s1_pick", "s2_place_inside", "s9_close_container"]


def test_what_holds_only_once_the_container_is_shut_is_checked_after_the_shut_step():
    """keep_sharp_away_from_children also asks the knife out of a child's reach, which a safe standing
    open for the place cannot give: the place checks 'inside', the shut step the rest."""
    spec = _spec([_lid(0.0)])
    plan = plan_from_kb("t", "keep_sharp_away_from_children", dict(spec.bindings), spec=spec)
    place = next(s for s in plan.subtasks if s.id.endswith("place_inside"))
    shut = plan.subtasks[-1]
    assert [p.name for p in place.success.predicates] == ["inside"]
    assert [(p.name, p.negate) for p in shut.success.predicates] == [("joint_closed", False), ("child_reachable", True)]
    assert {p.name for p in plan.success.predicates} >= {"inside", "child_reachable"}  # the task's own is unchanged
