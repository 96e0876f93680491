"""The LLM planning engine: reply schema, scene-bound validation, repair, and the plan stage on a run folder.

LLM replies come from the scripted OpenAI-compatible server (real HTTP through the LLM layer); scenes
are SceneSpec JSON written directly (the planner reads names and joints, never MuJoCo).
"""

from __future__ import annotations

import json
import re

import pytest

from anomalygen.config import load_settings
from anomalygen.llm import get_client
from anomalygen.plan import llm_prompt as Prompt
from anomalygen.plan import plan_llm as P
from anomalygen.plan.stage import run_stage
from anomalygen.runfolder import RunFolder, read_model, write_jsonl, write_model
from anomalygen.schema import (
    AssetRef,
    Engine,
    HazardCategory,
    ItemError,
    JointState,
    ObjectRole,
    PlacedObject,
    Plan,
    PredicateCall,
    Provenance,
    RewardTerm,
    Scenario,
    SceneSpec,
    SkillMethod,
    TaskProposal,
)
from support.fixtures import llm_config_for, scripted_server  # noqa: F401
from support.openai_server import text
from support.perceived import graph_of

# --------------------------------------------------------------------------- scenes and tasks


def _obj(name, category, role, *, support="floor", fixed=False, joints=()):
    return PlacedObject(name=name, asset=AssetRef(asset_id=f"test-{category}", category=category), role=role,
                        size=0.3, pos=[0.5, 0.0, 0.9], support=support, fixed=fixed, joint_states=list(joints))


def knife_scene() -> SceneSpec:
    drawer = JointState(name="cabinet_0/drawer_slide", label="drawer", type="slide", value=0.3, range=(0.0, 0.35),
                        closed_value=0.0)
    return SceneSpec(scene_id="t-knife", task_id="t-knife", room="kitchen", seed=0, objects=[
        _obj("counter_0", "counter", ObjectRole.SUPPORT, fixed=True),
        _obj("knife_0", "Knife", ObjectRole.HAZARD, support="counter_0:top"),
        _obj("cabinet_0", "StorageFurniture", ObjectRole.CONTAINER, fixed=True, joints=[drawer]),
        _obj("mug_0", "mug", ObjectRole.CLUTTER, support="counter_0:top"),
    ], bindings={"$hazard": "knife_0", "$container": "cabinet_0"})


def fridge_scene() -> SceneSpec:
    door = JointState(name="refrigerator_0/door_hinge", label="door", value=1.2, range=(0.0, 1.9), closed_value=0.0)
    return SceneSpec(scene_id="t-fridge", task_id="t-fridge", room="kitchen", seed=0, objects=[
        _obj("refrigerator_0", "Refrigerator", ObjectRole.TARGET, fixed=True, joints=[door]),
        _obj("apple_0", "apple", ObjectRole.CLUTTER),
    ], bindings={"$target": "refrigerator_0"})


def task(tid: str, hazard_class: str, name: str) -> TaskProposal:
    return TaskProposal(id=tid, name=name, explanation="e", description=f"{name}, in the kitchen.",
                        category=HazardCategory.HOUSEHOLD_HAZARD, hazard_class=hazard_class, target_asset="Knife",
                        scenario=Scenario(hazard_object="knife", room="kitchen", placement="counter_edge"),
                        solution="Put it right.", provenance=Provenance(engine=Engine.KNOWLEDGE, mode="plain"))


# --------------------------------------------------------------------------- scripted replies


def pred(name, negate=False, **args):
    return {"name": name, "args": args, "negate": negate}


KNIFE_REPLY = {
    "subtasks": [
        {"id": "s1_pick", "description": "lift the knife off the counter", "method": "primitive", "primitive": "grasp",
         "params": {"object": "$hazard", "lift": 0.1},
         "reward": [{"kind": "distance", "a": "ee", "b": "knife_0", "weight": 1.0},
                    {"kind": "lifted", "a": "$hazard", "target": 1.0, "weight": 2.0}]},
        {"id": "s2_store", "description": "put the knife in the open drawer", "method": "primitive",
         "primitive": "move_to", "params": {"object": "knife_0", "region": "$container", "release": True},
         "success": [pred("inside", object="$hazard", container="$container")]},
        {"id": "s3_close", "description": "slide the drawer shut by contact", "method": "sac",
         "params": {"object": "cabinet_0", "joint": "drawer_slide", "target": 0.0},
         "reward": [{"kind": "joint", "joint": "cabinet_0/drawer_slide", "target": 0.0, "weight": 2.0},
                    {"kind": "action_penalty", "weight": 0.01}],
         "success": [pred("joint_closed", object="$container", label="drawer", max_fraction="0.1")]},
    ],
    "success": [pred("inside", object="$hazard", container="$container"), pred("on", True, object="$hazard", support="*")],
}

FRIDGE_REPLY = {
    "subtasks": [{"id": "s1_close", "description": "push the fridge door shut", "method": "primitive",
                  "primitive": "push", "params": {"object": "$target", "part": "door", "target": 0.0}}],
    "success": [pred("joint_closed", object="$target", label="door")],
}


def _user(req) -> str:
    return [m for m in req["messages"] if m["role"] == "user"][-1]["content"]


def _repairing(req) -> bool:
    """A repair turn: the conversation continues after this scene's own question."""
    return req["messages"][-1]["content"].startswith("Your previous reply could not be used")


def _scene_question(req) -> str:
    users = [m["content"] for m in req["messages"] if m["role"] == "user"]
    return users[len(Prompt.load_examples())]  # the examples' questions come first


# --------------------------------------------------------------------------- the engine


def test_a_good_reply_becomes_the_plan_it_describes(scripted_server, tmp_path):  # noqa: F811
    srv = scripted_server([text(json.dumps(KNIFE_REPLY))])
    client = get_client(llm_config_for(srv, tmp_path, cache=False))
    spec = knife_scene()
    plan = P.plan_from_llm("t-knife", "store_sharp_objects", dict(spec.bindings), spec=spec, client=client,
                           hazard="A knife lies at the counter edge.")
    assert isinstance(plan, Plan) and plan.engine == Engine.LLM and plan.source == "ground_truth"
    assert plan.bindings == {"$hazard": "knife_0", "$container": "cabinet_0"}
    assert [(s.id, s.method, s.primitive) for s in plan.subtasks] == [
        ("s1_pick", SkillMethod.PRIMITIVE, "grasp"), ("s2_store", SkillMethod.PRIMITIVE, "move_to"),
        ("s3_close", SkillMethod.SAC, None)]
    # role variables resolved in params and rewards (the executor reads instance names), short joint name expanded
    assert plan.subtasks[0].params == {"object": "knife_0", "lift": 0.1}
    assert plan.subtasks[1].params == {"object": "knife_0", "region": "cabinet_0", "release": True}
    assert plan.subtasks[2].params == {"object": "cabinet_0", "joint": "cabinet_0/drawer_slide", "target": 0.0}
    assert plan.subtasks[0].reward.terms == [RewardTerm(kind="distance", a="ee", b="knife_0", weight=1.0),
                                             RewardTerm(kind="lifted", a="knife_0", target=1.0, weight=2.0)]
    assert plan.subtasks[1].reward is None
    assert plan.subtasks[2].reward.terms[0] == RewardTerm(kind="joint", joint="cabinet_0/drawer_slide", target=0.0,
                                                          weight=2.0)
    # predicates keep their role variables; numeric strings become numbers
    assert plan.subtasks[2].success.predicates == [
        PredicateCall(name="joint_closed", args={"object": "$container", "label": "drawer", "max_fraction": 0.1})]
    assert plan.success.predicates == [
        PredicateCall(name="inside", args={"object": "$hazard", "container": "$container"}),
        PredicateCall(name="on", args={"object": "$hazard", "support": "*"}, negate=True)]
    # what the model was shown: the scene with its joint, the menus, three examples, the hazard
    (req,) = srv.requests
    system = req["messages"][0]["content"]
    assert "push(" in system and "joint_closed(" in system and "action_penalty" in system
    assert sum(m["role"] == "assistant" for m in req["messages"]) == 3
    question = _user(req)
    assert "cabinet_0/drawer_slide: drawer slide" in question and "knife_0 (Knife)" in question
    assert "$hazard = knife_0" in question and "A knife lies at the counter edge." in question
    assert "store_sharp_objects" in question and "role" not in question.split("Hazard class")[0]


def test_a_loosely_named_object_is_grounded_without_a_repair(scripted_server, tmp_path):  # noqa: F811
    loose = json.loads(json.dumps(FRIDGE_REPLY))
    loose["subtasks"][0]["params"]["object"] = "the Fridge"
    srv = scripted_server([text(json.dumps(loose))])
    client = get_client(llm_config_for(srv, tmp_path, cache=False))
    spec = fridge_scene()
    plan = P.plan_from_llm("t-fridge", "close_open_refrigerator", dict(spec.bindings), spec=spec, client=client)
    assert plan.subtasks[0].params == {"object": "refrigerator_0", "part": "door", "target": 0.0}
    assert len(srv.requests) == 1 and client.usage.retries == 0


def test_a_reply_naming_an_object_not_in_the_scene_is_repaired(scripted_server, tmp_path):  # noqa: F811
    bad = json.loads(json.dumps(FRIDGE_REPLY))
    bad["subtasks"][0]["params"]["object"] = "flux_capacitor"

    def responder(req):
        return text(json.dumps(FRIDGE_REPLY if _repairing(req) else bad))

    srv = scripted_server(responder)
    client = get_client(llm_config_for(srv, tmp_path, cache=False))
    spec = fridge_scene()
    plan = P.plan_from_llm("t-fridge", "close_open_refrigerator", dict(spec.bindings), spec=spec, client=client)
    assert plan.subtasks[0].params == {"object": "refrigerator_0", "part": "door", "target": 0.0}
    assert len(srv.requests) == 2
    repair = srv.requests[1]["messages"][-1]["content"]
    assert "'flux_capacitor' is not an object in the scene" in repair and "refrigerator_0" in repair
    assert client.usage.requests == 2 and client.usage.retries == 1


@pytest.mark.parametrize(("change", "expected"), [
    (lambda r: r["success"].append(pred("is_sharp", object="$hazard")), "unknown predicate 'is_sharp'"),
    (lambda r: r["success"].append(pred("on_floor", object="$hazard", colour="red")), "takes no argument 'colour'"),
    (lambda r: r["success"].append(pred("inside", container="$container")), "needs argument 'object'"),
    (lambda r: r["success"].append(pred("on_floor", object="$target")), "role variable $target is not bound"),
    (lambda r: r["success"].append(pred("near_edge", object="$hazard", max_distance="far")), "must be a number"),
    (lambda r: r["success"].append(pred("joint_open", object="cabinet_0", label="lid")), "no joint labelled 'lid'"),
    (lambda r: r["success"].append(pred("has_property", object="knife_0", property="pointy")), "unknown property"),
    (lambda r: r["subtasks"][0].update(primitive="teleport"), "unknown primitive 'teleport'"),
    (lambda r: r["subtasks"][0].update(primitive=None), "method primitive needs a primitive"),
    (lambda r: r["subtasks"][1]["params"].pop("region"), "move_to needs params.region"),
    (lambda r: r["subtasks"][2]["params"].update(joint="door_hinge"), "'door_hinge' is not a joint of object 'cabinet_0'"),
    (lambda r: r["subtasks"][2]["params"].update(target=2.0), "outside the range"),
    (lambda r: r["subtasks"][2].update(reward=[{"kind": "action_penalty"}]), "sac learns from its reward"),
    (lambda r: r["subtasks"][0]["reward"].append({"kind": "joint", "target": 0.0}), "a joint term needs 'joint'"),
    (lambda r: r["subtasks"][0]["reward"].append({"kind": "inside", "a": "knife_0", "b": "ee"}), "'ee' is the gripper"),
    (lambda r: r["subtasks"][1].update(id="s1_pick"), "duplicate sub-task id"),
])
def test_semantic_problems_are_named(change, expected):
    reply = json.loads(json.dumps(KNIFE_REPLY))
    change(reply)
    spec = knife_scene()
    scene = P.PlanScene(spec, dict(spec.bindings))
    problems = P.check_reply(P.TaskPlan.model_validate(reply), scene)
    assert any(expected in p for p in problems), problems
    with pytest.raises(ValueError, match="Value error"):
        P.reply_schema(scene).model_validate(reply)


def test_empty_plans_are_rejected_by_the_schema():
    scene = P.PlanScene(knife_scene(), {})
    schema = P.reply_schema(scene)
    with pytest.raises(ValueError, match="at least 1 item"):
        schema.model_validate({"subtasks": [], "success": [pred("on_floor", object="knife_0")]})
    with pytest.raises(ValueError, match="at least 1 item"):
        schema.model_validate({"subtasks": KNIFE_REPLY["subtasks"][:1], "success": []})


def test_the_schema_advertises_this_scenes_names():
    schema = P.reply_schema(P.PlanScene(knife_scene(), {"$hazard": "knife_0"})).model_json_schema()
    params = schema["$defs"]["ReplyParams"]["properties"]
    assert params["object"]["anyOf"][0]["enum"] == ["$hazard", "cabinet_0", "counter_0", "knife_0", "mug_0"]
    assert params["joint"]["anyOf"][0]["enum"] == ["cabinet_0/drawer_slide"]
    assert schema["$defs"]["ReplySubTask"]["properties"]["primitive"]["anyOf"][0]["enum"] == sorted(Prompt.PRIMITIVES)


def test_every_in_context_example_is_a_valid_plan_of_its_own_scene():
    examples = Prompt.load_examples()
    assert len(examples) == 3
    methods = set()
    for ex in examples:
        scene = P.PlanScene(ex.spec, dict(ex.spec.bindings))
        reply = P.reply_schema(scene).model_validate(ex.answer)
        plan = P.to_plan(reply, scene, ex.spec.task_id)
        methods |= {st.method for st in plan.subtasks}
    assert methods == {SkillMethod.PRIMITIVE, SkillMethod.SAC}


def test_cem_is_not_offered_to_the_llm_planner():
    """CEM runs only on the Gymnasium Ant: the prompt does not offer it and a reply using it is refused."""
    assert not re.search(r"\bcem\b", Prompt.SYSTEM_PROMPT.lower())
    assert all(st["method"] != "cem" for ex in Prompt.load_examples() for st in ex.answer["subtasks"])
    ex = Prompt.load_examples()[0]
    scene = P.PlanScene(ex.spec, dict(ex.spec.bindings))
    bad = {**ex.answer, "subtasks": [{**ex.answer["subtasks"][0], "method": "cem"}, *ex.answer["subtasks"][1:]]}
    with pytest.raises(Exception, match="primitive"):
        P.reply_schema(scene).model_validate(bad)
    schema = P.reply_schema(scene).model_json_schema()
    assert "cem" not in json.dumps(schema["$defs"]["ReplySubTask"]["properties"]["method"])


def test_a_binding_outside_the_scene_fails_before_asking():
    spec = fridge_scene()
    with pytest.raises(Exception, match=r"\$hazard is bound to 'fridge', which is not an object"):
        P.plan_from_llm("t", "close_open_refrigerator", {"$hazard": "fridge"}, spec=spec, client=None)


# --------------------------------------------------------------------------- the plan stage


def _run(tmp_path) -> RunFolder:
    run = RunFolder.create(tmp_path / "run")
    write_jsonl(run.tasks_path, [task("t-knife", "store_sharp_objects", "Knife on the counter"),
                                 task("t-fridge", "close_open_refrigerator", "Fridge left open")])
    for tid, spec in (("t-knife", knife_scene()), ("t-fridge", fridge_scene())):
        write_model(run.scene_dir(tid) / "scene.json", spec)
        write_model(run.scene_dir(tid) / "scene_graph.json", graph_of(spec))
    return run


def _settings(srv, tmp_path, **over):
    # the oracle unless a test asks otherwise: these tests exercise the LLM planner on the task's own class
    s = load_settings(None, {"quiet": True, "workers": 1, "plan.engine": "llm", "plan.source": "ground_truth",
                             **over})
    s.llm = llm_config_for(srv, tmp_path, cache=False)
    return s


def test_plan_stage_fails_the_item_whose_replies_never_validate_and_plans_the_other(scripted_server, tmp_path):  # noqa: F811
    def responder(req):
        if "knife_0" in _scene_question(req):
            return text("First I would pick up the knife, then store it.")  # never JSON
        return text(json.dumps(FRIDGE_REPLY))

    srv = scripted_server(responder)
    run = _run(tmp_path)
    summary = run_stage(run, _settings(srv, tmp_path))
    assert (summary.done, summary.failed) == (1, 1)
    plan = read_model(run.plan_path("t-fridge"), Plan)
    assert plan.engine == Engine.LLM and plan.bindings == {"$target": "refrigerator_0"}
    assert plan.subtasks[0].primitive == "push" and plan.subtasks[0].params["object"] == "refrigerator_0"
    assert "Fridge left open" in _scene_question(next(r for r in srv.requests if "apple_0" in _scene_question(r)))
    assert not run.plan_path("t-knife").exists()
    err = read_model(run.error_path("plan", "t-knife"), ItemError)
    assert err.error.startswith("LLM reply is not a valid TaskPlan after 3 attempt(s)") and "\n" not in err.error
    # 3 attempts for the knife, 1 for the fridge; every request (the failed item's too) is in the manifest
    assert len(srv.requests) == 4
    usage = run.load_manifest().llm_usage
    assert usage.requests == 4 and usage.prompt_tokens == 4 * 11 and usage.retries == 2
    # a re-run keeps the good plan and asks again only for the failed item
    again = run_stage(run, _settings(srv, tmp_path))
    assert (again.skipped, again.failed) == (1, 1) and len(srv.requests) == 7


def test_plan_stage_detected_source_shows_the_detection_not_the_task(scripted_server, tmp_path):  # noqa: F811
    from anomalygen.schema import Detection, Hypothesis

    srv = scripted_server([text(json.dumps(FRIDGE_REPLY))])
    run = _run(tmp_path)
    hyp = Hypothesis(rank=1, problem="The fridge door hangs open.", solution="Shut it.", target_object="refrigerator_0",
                     hazard_class="close_open_refrigerator")
    write_jsonl(run.detections_path, [Detection(task_id="t-fridge", scene_id="t-fridge", detector="rules",
                                                hypotheses=[hyp])])
    summary = run_stage(run, _settings(srv, tmp_path, **{"plan.source": "detected"}), only=["t-fridge"])
    assert summary.done == 1
    plan = read_model(run.plan_path("t-fridge"), Plan)
    assert plan.source == "detected" and plan.bindings == {"$target": "refrigerator_0"}
    question = _scene_question(srv.requests[0])
    assert "The fridge door hangs open." in question and "Fridge left open" not in question


def test_plan_stage_llm_engine_without_an_llm_says_so(tmp_path):
    from anomalygen.errors import UserError

    run = _run(tmp_path)
    with pytest.raises(UserError, match="needs an LLM"):
        run_stage(run, load_settings(None, {"quiet": True, "plan.engine": "llm"}))


# --------------------------------------------------------------------------- the real tiny model


@pytest.mark.slow
@pytest.mark.gguf
def test_plan_stage_on_the_bundled_gguf_ends_each_item_cleanly(tmp_path):
    from anomalygen.config import LLMConfig

    run = _run(tmp_path)
    settings = load_settings(None, {"quiet": True, "workers": 1, "plan.engine": "llm",
                                    "plan.source": "ground_truth"})
    settings.llm = LLMConfig(backend="llamacpp", cache=False, max_tokens=300, repair_retries=0)
    summary = run_stage(run, settings, only=["t-fridge"])
    assert summary.done + summary.failed == 1
    if summary.done:  # the grammar kept it to the scene's names and the validator accepted it
        plan = read_model(run.plan_path("t-fridge"), Plan)
        assert plan.engine == Engine.LLM and plan.subtasks and plan.success.predicates
    else:  # SmolLM2-135M mostly writes nonsense: that must end as one clean line, not a crash
        err = read_model(run.error_path("plan", "t-fridge"), ItemError).error
        assert "\n" not in err and ("TaskPlan" in err or "llamacpp" in err), err
    usage = run.load_manifest().llm_usage
    assert usage.requests >= 1 and usage.completion_tokens > 0


def _fridge_plan_from(tmp_path, claims: list[tuple[str, str]]) -> Plan:
    """The plan from perception for the fridge scene, given the detector's (object, class) claims in rank order."""
    from anomalygen.schema import Detection, Hypothesis

    run = _run(tmp_path)
    hyps = [Hypothesis(rank=k, problem="p", solution="s", target_object=obj, hazard_class=cls, score=0.9)
            for k, (obj, cls) in enumerate(claims, start=1)]
    write_jsonl(run.detections_path, [Detection(task_id="t-fridge", scene_id="t-fridge", detector="rules",
                                                hypotheses=hyps)])
    settings = load_settings(None, {"quiet": True, "workers": 1, "plan.source": "detected"})
    assert run_stage(run, settings, only=["t-fridge"]).done == 1
    return read_model(run.plan_path("t-fridge"), Plan)


def test_a_detected_fix_that_cannot_be_bound_is_recorded_in_the_plan_not_dropped_silently(tmp_path):
    """Two detected hazards, one with nothing in the scene to fix it with (litter, no bin): the plan
    makes the other fix and names the dropped one with the planner's reason, for reports to show."""
    from anomalygen.schema import DroppedFix

    plan = _fridge_plan_from(tmp_path, [("refrigerator_0", "close_open_refrigerator"), ("apple_0", "pick_up_floor_litter")])
    assert plan.subtasks and all(s.params.get("object") == "refrigerator_0" for s in plan.subtasks)
    (dropped,) = plan.dropped
    assert isinstance(dropped, DroppedFix)
    assert (dropped.hazard_class, dropped.object) == ("pick_up_floor_litter", "apple_0")
    assert "no reachable container for apple_0" in dropped.reason and "TrashCan" in dropped.reason


def test_when_an_objects_most_severe_class_cannot_be_bound_its_next_class_is_planned(tmp_path):
    """Toys on the stairs are also a choking hazard; with no box to put a toy in, the plan takes it off
    the stairs instead of failing the scene. Here: a class with nothing to bind it to (no bin) ranks
    above the fridge's own; the fridge is still closed and the other class is named as dropped."""
    plan = _fridge_plan_from(tmp_path, [("refrigerator_0", "dispose_spoiled_food"), ("refrigerator_0", "close_open_refrigerator")])
    assert plan.bindings.get("$target") == "refrigerator_0"
    assert [s.id for s in plan.subtasks] == ["s1_close_joint"]
    assert [(d.hazard_class, d.object) for d in plan.dropped] == [("dispose_spoiled_food", "refrigerator_0")]
