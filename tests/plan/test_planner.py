"""KB-recipe plans: every class with a recipe yields typed sub-tasks bound to scene instances."""

import pytest

from anomalygen.errors import ItemFailed
from anomalygen.knowledge.base import load_kb
from anomalygen.plan.planner import plan_from_kb, plannable
from anomalygen.schema import Plan, SkillMethod


def test_every_kb_class_plans():
    """Every class plans, except those whose fix needs a skill the robot does not have yet: they fail
    saying which (never a substitute step)."""
    kb = load_kb()
    for cid, hc in kb.hazard_classes.items():
        bindings = {v: f"{v.lstrip('$')}_0" for v in hc.recipe_variable_names()}
        missing = [s.action for s in hc.recipe if not plannable(s.action)]
        if missing:
            with pytest.raises(ItemFailed, match=f"no skill for {missing[0]} yet"):
                plan_from_kb("t", cid, bindings)
            continue
        plan = plan_from_kb("t", cid, bindings)
        assert isinstance(plan, Plan) and plan.subtasks
        assert plan.success.predicates == list(hc.success)
        sac_steps = {step.action for step in hc.recipe if step.method == "sac"}
        for st in plan.subtasks:
            learned = any(st.id.startswith(f"s{i + 1}_{a}") for i, step in enumerate(hc.recipe)
                          for a in sac_steps if step.action == a)
            assert st.method == (SkillMethod.SAC if learned else SkillMethod.PRIMITIVE) and st.reward is not None
            assert not any(str(v).startswith("$") for v in st.params.values())


def test_store_plan_is_pick_then_place_inside():
    plan = plan_from_kb("t", "store_sharp_objects", {"$hazard": "knife_0", "$container": "drawer_0"})
    assert [s.primitive for s in plan.subtasks] == ["grasp", "move_to"]
    assert plan.subtasks[1].params["region"] == "drawer_0"
    kinds = [t.kind for t in plan.subtasks[1].reward.terms]
    assert "inside" in kinds
    # the final step carries the class's success predicate
    assert plan.subtasks[1].success.predicates[0].name == "inside"


def _task(tid, hazard_class):
    from anomalygen.schema import Engine, HazardCategory, Provenance, Scenario, TaskProposal

    return TaskProposal(id=tid, name="n", explanation="e", description="d", category=HazardCategory.HOUSEHOLD_HAZARD,
                        hazard_class=hazard_class, target_asset="knife",
                        scenario=Scenario(hazard_object="knife", room="kitchen", placement="counter_edge"),
                        provenance=Provenance(engine=Engine.KNOWLEDGE, mode="plain"))


def test_plan_stage_writes_plans_and_fails_one_item(tmp_path):
    from anomalygen.config import Settings
    from anomalygen.plan.stage import run_stage
    from anomalygen.runfolder import RunFolder, read_model, write_jsonl

    run = RunFolder.create(tmp_path / "r")
    write_jsonl(run.tasks_path, [_task("a", "store_sharp_objects"), _task("b", "no_such_class")])
    oracle = Settings(quiet=True, plan={"source": "ground_truth"})
    summary = run_stage(run, oracle)
    assert summary.done == 1 and summary.failed == 1 and "b" in summary.errors
    plan = read_model(run.plan_path("a"), Plan)
    assert plan.source == "ground_truth" and len(plan.subtasks) == 2
    again = run_stage(run, oracle)
    assert again.skipped == 1


def _scene_with_a_drawer_and_two_sharp_things(run, tid):
    """A kitchen: scissors and a knife on the counter, a cabinet with a shut drawer, a bin."""
    from anomalygen.runfolder import write_model
    from anomalygen.schema import AssetRef, JointState, ObjectRole, PlacedObject, SceneSpec
    from support.perceived import graph_of

    def placed(name, category, pos, size, role, joints=(), fixed=False):
        return PlacedObject(name=name, asset=AssetRef(asset_id=f"{category}-0", category=category, source="procedural"),
                            role=role, size=size, pos=list(pos), quat=[1, 0, 0, 0], joint_states=list(joints), fixed=fixed)

    drawer = JointState(name="storagefurniture_0/drawer", label="drawer", type="slide", value=0.0, range=(0.0, 0.35),
                        closed_value=0.0)
    spec = SceneSpec(scene_id="s", task_id=tid, room="kitchen", seed=0, bindings={"$hazard": "knife_0",
                     "$container": "storagefurniture_0"}, objects=[
        placed("counter_0", "counter", (0.5, 1.6, 0.45), 0.9, ObjectRole.SUPPORT, fixed=True),
        placed("knife_0", "kitchen_knife", (0.6, 1.35, 0.92), 0.25, ObjectRole.HAZARD),
        placed("scissors_0", "scissors", (0.9, 1.5, 0.92), 0.18, ObjectRole.CLUTTER),
        placed("storagefurniture_0", "StorageFurniture", (1.8, 1.6, 0.45), 0.9, ObjectRole.CONTAINER, [drawer], True),
        placed("trashcan_0", "TrashCan", (0.0, 0.0, 0.2), 0.4, ObjectRole.AUXILIARY, fixed=True),
    ])
    write_model(run.scene_dir(tid) / "scene.json", spec)
    write_model(run.scene_dir(tid) / "scene_graph.json", graph_of(spec))
    return spec


def test_detected_plans_fix_every_hazard_most_severe_first_with_roles_chosen_from_the_scene(tmp_path):
    from anomalygen.config import Settings
    from anomalygen.plan.stage import run_stage
    from anomalygen.runfolder import RunFolder, read_model, write_jsonl
    from anomalygen.schema import Detection, Hypothesis

    run = RunFolder.create(tmp_path / "r")
    write_jsonl(run.tasks_path, [_task("a", "store_sharp_objects"), _task("quiet", "store_sharp_objects")])
    _scene_with_a_drawer_and_two_sharp_things(run, "a")
    _scene_with_a_drawer_and_two_sharp_things(run, "quiet")
    hyps = [Hypothesis(rank=1, problem="p", solution="s", target_object="scissors_0", hazard_class="store_sharp_objects",
                       score=0.75),
            Hypothesis(rank=2, problem="p", solution="s", target_object="knife_0", hazard_class="keep_sharp_away_from_children",
                       score=0.95),
            Hypothesis(rank=3, problem="p", solution="s", target_object="knife_0", hazard_class="store_sharp_objects",
                       score=0.75),  # same object again: not a second fix
            Hypothesis(rank=4, problem="p", solution="s", target_object="trashcan_0", hazard_class=None)]
    write_jsonl(run.detections_path, [Detection(task_id="a", scene_id="s", detector="rules", hypotheses=hyps),
                                      Detection(task_id="quiet", scene_id="s", detector="rules", hypotheses=[])])
    assert run_stage(run, Settings(quiet=True)).done == 2  # detected is the default
    plan = read_model(run.plan_path("a"), Plan)
    assert plan.source == "detected"
    # the more severe class first; the drawer is opened, used and shut for each; no $variables are left
    picks = [s.params["object"] for s in plan.subtasks if s.primitive == "grasp"]
    assert picks == ["knife_0", "scissors_0"]
    assert {s.params["region"] for s in plan.subtasks if s.primitive == "move_to"} == {"storagefurniture_0"}
    assert [s.id for s in plan.subtasks if "container" in s.id] == [
        "h1_s0_open_container", "h1_s9_close_container", "h2_s0_open_container", "h2_s9_close_container"]
    for call in plan.success.predicates + [c for s in plan.subtasks for c in s.success.predicates]:
        assert not any(str(v).startswith("$") for v in call.args.values()), call
    assert read_model(run.plan_path("quiet"), Plan).subtasks == []  # nothing detected: leave the scene alone


def test_the_perceived_spec_carries_no_answer_key(tmp_path):
    from anomalygen.runfolder import RunFolder
    from anomalygen.schema import ObjectRole
    from anomalygen.world.perception import load_perceived_spec

    run = RunFolder.create(tmp_path / "r")
    spec = _scene_with_a_drawer_and_two_sharp_things(run, "a")
    seen = load_perceived_spec(run.scene_dir("a"))
    assert spec.bindings and seen.bindings == {} and seen.task_id == ""
    assert {o.role for o in seen.objects} == {ObjectRole.AUXILIARY}
    assert [o.pos for o in seen.objects] == [o.pos for o in spec.objects]


def test_a_fix_with_no_container_in_the_scene_fails_with_the_reason(tmp_path):
    from anomalygen.errors import ItemFailed
    from anomalygen.knowledge import load_kb
    from anomalygen.plan.bind import bind_fix
    from anomalygen.runfolder import RunFolder
    from anomalygen.world.perception import load_scene_graph

    run = RunFolder.create(tmp_path / "r")
    _scene_with_a_drawer_and_two_sharp_things(run, "a")
    graph = load_scene_graph(run.scene_dir("a"))
    kb = load_kb()
    assert bind_fix(kb.hazard_classes["dispose_spoiled_food"], "knife_0", graph, kb)["$container"] == "trashcan_0"
    graph.objects = [o for o in graph.objects if o.name != "trashcan_0"]
    import pytest

    with pytest.raises(ItemFailed, match="no reachable container for knife_0"):
        bind_fix(kb.hazard_classes["dispose_spoiled_food"], "knife_0", graph, kb)


def test_offline_planner_picks_sac_for_switch_off_per_knob_that_is_on():
    """The KB marks switch_off as a SAC step: one sub-task per knob that is on, most on first, each with
    a reward on its travel to off (scaled by 1 / travel) and the cup near the knob."""
    from anomalygen.schema import AssetRef, JointState, ObjectRole, PlacedObject, SceneSpec

    knobs = [JointState(name=f"oven_0/knob_{k}_joint", label="knob", value=v, range=(0.0, 4.7), closed_value=0.0)
             for k, v in enumerate((3.5, 0.0, 4.2))]
    oven = PlacedObject(name="oven_0", asset=AssetRef(category="Oven", asset_id="oven"),
                        role=ObjectRole.TARGET, size=0.9, pos=(0.0, 0.0, 0.0), joint_states=knobs)
    spec = SceneSpec(scene_id="t", task_id="t", room="kitchen", seed=0, objects=[oven])
    plan = plan_from_kb("t", "switch_off_appliance", {"$target": "oven_0"}, spec=spec)
    assert [st.method for st in plan.subtasks] == [SkillMethod.SAC, SkillMethod.SAC]
    assert [st.params["joint"] for st in plan.subtasks] == ["oven_0/knob_2_joint", "oven_0/knob_0_joint"]
    joint = plan.subtasks[0].reward.terms[0]
    assert joint.kind == "joint" and joint.target == 0.0 and abs(joint.scale - 1 / 4.7) < 1e-9
    assert plan.subtasks[0].reward.terms[1].b == "oven_0/knob_2_joint"
    assert plan.subtasks[-1].success.predicates and not plan.subtasks[0].success.predicates
    # other classes stay primitive unless the user lists their actions
    assert all(st.method == SkillMethod.PRIMITIVE for st in plan_from_kb(
        "t", "close_open_refrigerator", {"$target": "fridge_0"}).subtasks)


def test_relocations_are_their_registered_skills_and_unbound_variables_fail():
    """take_off, move_away and rotate_inward are one scripted skill each (``skills/scripted/relocate.py``),
    their arguments resolved to instances; standing an iron upright has no skill yet and says so."""
    plan = plan_from_kb("t", "clear_burning_risk_off_heat_source",
                        {"$hazard": "towel_0", "$source": "stove_0", "$support": "counter_0"})
    assert [(s.primitive, s.params.get("object")) for s in plan.subtasks] == [("push", "stove_0"), ("take_off", "towel_0")]
    assert plan.subtasks[-1].params["support"] == "counter_0"
    assert [c.name for c in plan.subtasks[-1].success.predicates] == ["on"]  # the class's check on this step's objects
    away = plan_from_kb("t", "move_candle_away_from_fabric", {"$hazard": "candle_0", "$fuel": "curtains_0"}).subtasks
    assert [(s.primitive, s.params) for s in away] == [
        ("move_away", {"object": "candle_0", "from": "curtains_0", "distance": 0.9})]
    turn = plan_from_kb("t", "turn_pan_handle_inward", {"$hazard": "pot_0"}).subtasks
    assert [(s.primitive, s.params) for s in turn] == [("rotate_inward", {"object": "pot_0"})]
    with pytest.raises(ItemFailed, match=r"\$source is not bound"):
        plan_from_kb("t", "clear_burning_risk_off_heat_source", {"$hazard": "towel_0", "$support": "counter_0"})
    with pytest.raises(ItemFailed, match="no skill for stand_upright yet"):
        plan_from_kb("t", "stand_iron_upright", {"$hazard": "iron_0"})


def test_brainstorm_draws_the_relocation_classes_and_says_why_not_the_upright_iron():
    from anomalygen.brainstorm.drawable import drawable, why_not_drawable

    kb = load_kb()
    for cid in ("turn_pan_handle_inward", "move_candle_away_from_fabric", "clear_item_from_stairs",
                "clear_burning_risk_off_heat_source", "close_baby_gate"):
        assert drawable(kb, kb.hazard_classes[cid]), why_not_drawable(kb, kb.hazard_classes[cid])
    assert why_not_drawable(kb, kb.hazard_classes["stand_iron_upright"]) == (
        "no skill for stand_upright yet: stand_iron_upright's fix needs it")
