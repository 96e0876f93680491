"""Decompose a fix into typed sub-tasks: knowledge-base recipes -> ``schema.Plan``.

Each recipe step becomes one sub-task with a method (motion-planned primitive by default, as the
paper picks primitives for reaching and placing), typed parameters naming scene instances, a
RewardSpec built from composable terms (so the same step can be learned by SAC instead), and a
SuccessSpec of knowledge-base predicates. Role variables are kept in the predicates and resolved
through ``Plan.bindings`` when evaluated, so a plan stays readable and checkable.
"""

from __future__ import annotations

from anomalygen.errors import ItemFailed
from anomalygen.schema import (
    DOOR,
    DRAWER,
    ENCLOSING_LABELS,
    LID_LABELS,
    SWITCH_LABELS,
    Engine,
    Plan,
    PredicateCall,
    RewardSpec,
    RewardTerm,
    SceneSpec,
    SkillMethod,
    SubTask,
    SuccessSpec,
    part_labels,
)

LIFT_HEIGHT = 0.12  # metres above the start height for a pick
#: Recipe actions the knowledge base knows but no skill performs yet: a plan with one fails with that
#: reason rather than doing something else (the skills come with the robot's skill library).
NO_SKILL_YET = ("stand_upright",)
#: Recipe actions that are one registered scripted skill of the same name (``skills/scripted/relocate.py``),
#: with the step's arguments passed through (variables resolved to instances).
RELOCATIONS = ("move_away", "take_off", "rotate_inward")
ROLE_VARIABLES = ("$hazard", "$target", "$container", "$support")  # what the builder binds in SceneSpec.bindings
CLOSURES = ENCLOSING_LABELS  # part labels that can shut a container, in the order a plan lists them
LID_PARTS = part_labels.any_of(LID_LABELS)  # the parts close_lid / open_lid act on (a cardboard box has flaps)
_LIFTED_OUT = 1.0  # m: reward target height for an object taken out of a counter-top appliance


def _resolve(value: str, bindings: dict[str, str]) -> str:
    return bindings.get(value, value) if value.startswith("$") else value


def _joint_of(spec: SceneSpec | None, instance: str) -> tuple[str | None, float | None]:
    """The articulated joint of ``instance`` (first one) and its closed value, from the scene spec."""
    if spec is None:
        return None, None
    for obj in spec.objects:
        if obj.name == instance and obj.joint_states:
            js = obj.joint_states[0]
            return js.name, js.closed_value
    return None, None


def _height_of(spec: SceneSpec | None, instance: str) -> float:
    if spec is not None:
        for obj in spec.objects:
            if obj.name == instance:
                return float(obj.pos[2])
    return 0.0


def plannable(action: str) -> bool:
    """Can a plan carry out this recipe action today?"""
    return action not in NO_SKILL_YET


def step_to_subtask(index: int, action: str, args: dict[str, str], bindings: dict[str, str],
                    spec: SceneSpec | None, final_success: list[PredicateCall]) -> SubTask:
    """One recipe step -> one sub-task (primitive, with a reward spec for RL fallback)."""
    if not plannable(action):
        raise ItemFailed(f"no skill for {action} yet: the step {action}({', '.join(f'{k}={v}' for k, v in args.items())}) "
                         "cannot be planned")
    obj = _resolve(args.get("object", "$hazard"), bindings)
    sid = f"s{index + 1}_{action}"
    # Success of a step: the class predicates that talk about this step's arguments.
    vars_here = set(args.values())
    own = [p for p in final_success if vars_here & {str(v) for v in p.args.values()}]
    if action == "pick":
        z = _height_of(spec, obj) + LIFT_HEIGHT
        return SubTask(id=sid, description=f"grasp {obj} by suction and lift it", method=SkillMethod.PRIMITIVE,
                       primitive="grasp", params={"object": obj, "lift": LIFT_HEIGHT},
                       reward=RewardSpec(terms=[RewardTerm(kind="distance", a="ee", b=obj, weight=1.0),
                                                RewardTerm(kind="lifted", a=obj, target=z, weight=2.0),
                                                RewardTerm(kind="action_penalty", weight=0.01)]))
    if action in ("place_inside", "place_on"):
        dest_key = "container" if action == "place_inside" else "support"
        dest = _resolve(args.get(dest_key, f"${dest_key}"), bindings)
        kind = "inside" if action == "place_inside" else "distance"
        return SubTask(id=sid, description=f"move {obj} {'into' if kind == 'inside' else 'onto'} {dest} and release it",
                       method=SkillMethod.PRIMITIVE, primitive="move_to", params={"object": obj, "region": dest, "release": True},
                       reward=RewardSpec(terms=[RewardTerm(kind=kind, a=obj, b=dest, weight=2.0),
                                                RewardTerm(kind="action_penalty", weight=0.01)]),
                       success=SuccessSpec(predicates=own))
    if action in ("close_joint", "open_joint", "switch_off"):
        target_obj = _resolve(args.get("object", "$target"), bindings)
        joint, closed = _joint_of(spec, target_obj)
        prim = {"close_joint": "push", "open_joint": "pull", "switch_off": "push"}[action]
        params: dict = {"object": target_obj}
        if args.get("part"):
            params["part"] = args["part"]
        if action == "open_joint" and args.get("fraction"):
            params["open_fraction"] = float(args["fraction"])
        terms = [RewardTerm(kind="action_penalty", weight=0.01)]
        if joint is not None:
            params["joint"] = joint
            params["target"] = float(closed if action != "open_joint" else (closed or 0.0) + 1.0)
            terms.insert(0, RewardTerm(kind="joint", joint=joint, target=params["target"], weight=2.0))
            terms.insert(1, RewardTerm(kind="distance", a="ee", b=target_obj, weight=0.5))
        return SubTask(id=sid, description=f"{action.replace('_', ' ')} of {target_obj}", method=SkillMethod.PRIMITIVE,
                       primitive=prim, params=params, reward=RewardSpec(terms=terms), success=SuccessSpec(predicates=own))
    if action == "move_away_from_edge":
        return SubTask(id=sid, description=f"move {obj} away from the edge of its surface", method=SkillMethod.PRIMITIVE,
                       primitive="move_to", params={"object": obj, "region": "surface_centre", "release": True},
                       reward=RewardSpec(terms=[RewardTerm(kind="action_penalty", weight=0.01)]),
                       success=SuccessSpec(predicates=own))
    if action in ("push_to", "take_out_of", "close_lid", "open_lid"):
        return _handling_subtask(sid, action, obj, args, bindings, own)
    if action in RELOCATIONS:
        return _relocation_subtask(sid, action, obj, args, bindings, own)
    raise ItemFailed(f"recipe action {action!r} has no sub-task mapping")


def _relocation_subtask(sid: str, action: str, obj: str, args: dict[str, str], bindings: dict[str, str],
                        own: list[PredicateCall]) -> SubTask:
    """move_away (from an object, by a distance), take_off (onto a support; the skill picks the nearest
    safe one when the recipe names none) and rotate_inward (a pan's handle back over its hob)."""
    params: dict = {"object": obj}
    terms = [RewardTerm(kind="action_penalty", weight=0.01)]
    if action == "move_away":
        params["from"] = _resolve(args["from"], bindings)
        params["distance"] = float(args["distance"])
        what = f"move {obj} at least {params['distance']:.2f} m away from {params['from']}"
    elif action == "take_off":
        support = _resolve(args.get("support", ""), bindings)
        if support and not support.startswith("$"):
            params["support"] = support
            terms.insert(0, RewardTerm(kind="distance", a=obj, b=support, weight=2.0))
        what = f"take {obj} off what it lies on and set it on {params.get('support', 'a safe surface')}"
    else:
        what = f"turn {obj} so its handle points back over its hob"
    return SubTask(id=sid, description=what, method=SkillMethod.PRIMITIVE, primitive=action, params=params,
                   reward=RewardSpec(terms=terms), success=SuccessSpec(predicates=own))


def switch_off_subtasks(index: int, args: dict[str, str], bindings: dict[str, str], spec: SceneSpec | None,
                        final_success: list[PredicateCall], method: SkillMethod) -> list[SubTask]:
    """A switch_off step -> one sub-task per knob or switch of the appliance that is on, most on first.

    The learned skill turns one part (``skills/learned/part_subtask.py``), and an oven has up to five knobs on; the
    scene spec (perceived joint values) says which. Each sub-task's reward is the part's travel to off
    as a fraction (the joint term scaled by 1 / travel, so a 4.7 rad knob and a 4 mm button weigh the
    same) plus the cup near the part; the class's predicates check the last one, earlier ones are
    checked by their joint term. With no part on in the spec (a plan from a wrong detection) the first
    part is planned, as for the other joint steps. ``args["joint"]`` (not a recipe argument) names one
    part, by its joint's name or the part of it after the object's name: only that part is planned.
    """
    target_obj = _resolve(args.get("object", "$target"), bindings)
    wanted = set(part_labels.alternatives(args["label"]) if "label" in args else SWITCH_LABELS)
    joints = [js for obj in (spec.objects if spec else []) if obj.name == target_obj
              for js in obj.joint_states if js.label in wanted]
    if args.get("joint"):  # one named part (a call of the skill-level env: switch_off(stove_0, knob_2))
        joints = [js for js in joints if args["joint"] in (js.name, js.name.split("/")[-1])]
    on = sorted([js for js in joints if not js.is_off()], key=lambda js: -js.open_fraction)
    chosen = on or joints[:1]
    vars_here = set(args.values())
    own = [p for p in final_success if vars_here & {str(v) for v in p.args.values()}]
    if not chosen:
        st = step_to_subtask(index, "switch_off", args, bindings, spec, final_success)
        return [st.model_copy(update={"method": method})]
    out = []
    for k, js in enumerate(chosen):
        lo, hi = js.range
        travel = max(abs(hi - lo), 1e-6)
        part = js.name.split("/")[-1]
        sid = f"s{index + 1}_switch_off" + (f"_{k + 1}" if len(chosen) > 1 else "")
        last = k == len(chosen) - 1
        out.append(SubTask(
            id=sid, description=f"switch off {target_obj}: turn {part} to off", method=method, primitive="push",
            params={"object": target_obj, "joint": js.name, "target": float(js.closed_value), "part": js.label,
                    "family": "switch_off"},
            reward=RewardSpec(terms=[RewardTerm(kind="joint", joint=js.name, target=float(js.closed_value), weight=2.0,
                                                scale=1.0 / travel),
                                     RewardTerm(kind="distance", a="ee", b=js.name, weight=0.5),
                                     RewardTerm(kind="action_penalty", weight=0.01)]),
            success=SuccessSpec(predicates=own if last else [])))
    return out


def _handling_subtask(sid: str, action: str, obj: str, args: dict[str, str], bindings: dict[str, str],
                      own: list[PredicateCall]) -> SubTask:
    """Sub-tasks of the actions that move whole objects along the floor, out of containers, or shut
    a portable container's lid. Each is a primitive of the same name (``learn/execute.py``)."""
    if action in ("close_lid", "open_lid"):
        verb = "close" if action == "close_lid" else "open"
        return SubTask(id=sid, description=f"{verb} the lid of {obj}", method=SkillMethod.PRIMITIVE, primitive=action,
                       params={"object": obj, "part": LID_PARTS},
                       reward=RewardSpec(terms=[RewardTerm(kind="distance", a="ee", b=obj, weight=0.5),
                                                RewardTerm(kind="action_penalty", weight=0.01)]),
                       success=SuccessSpec(predicates=own))
    key = "support" if action == "push_to" else "container"
    dest = _resolve(args.get(key, f"${key}"), bindings)
    if action == "push_to":
        return SubTask(id=sid, description=f"slide {obj} over the floor until it stands beside {dest}",
                       method=SkillMethod.PRIMITIVE, primitive="push_to", params={"object": obj, "region": dest},
                       reward=RewardSpec(terms=[RewardTerm(kind="distance", a=obj, b=dest, weight=2.0),
                                                RewardTerm(kind="action_penalty", weight=0.01)]),
                       success=SuccessSpec(predicates=own))
    # take_out_of: its own check is only that the object is out (it is still held afterwards).
    out = [p for p in own if p.name == "inside" and p.negate]
    return SubTask(id=sid, description=f"take {obj} out of {dest} and keep holding it", method=SkillMethod.PRIMITIVE,
                   primitive="take_out_of", params={"object": obj, "region": dest},
                   reward=RewardSpec(terms=[RewardTerm(kind="distance", a="ee", b=obj, weight=1.0),
                                            RewardTerm(kind="lifted", a=obj, target=_LIFTED_OUT, weight=2.0),
                                            RewardTerm(kind="action_penalty", weight=0.01)]),
                   success=SuccessSpec(predicates=out))


def closed_closures(spec: SceneSpec | None, instance: str) -> list[str]:
    """Labels of the container's lids, flaps, drawers and doors that are shut in the scene."""
    if spec is None:
        return []
    labels = {js.label for obj in spec.objects if obj.name == instance for js in obj.joint_states
              if js.label in CLOSURES and js.open_fraction < 0.1}
    return [lab for lab in CLOSURES if lab in labels]


def access_steps(container: str, labels: list[str], *, contents: str | None = None) -> tuple[SubTask, SubTask]:
    """Open a shut container before the pick (suction cannot hold an object and a lid at once) and
    shut it again after the place: a drawer left open is a hazard of its own. With ``contents`` the
    container is the one the object comes out of: the door or drawer in front of it is opened (the
    executor finds which from the scene) and shut again at the end."""
    part = part_labels.any_of(labels)
    which = "source" if contents else "container"
    why = f"to take {contents} out" if contents else "to put something inside"
    params = {"object": container, "part": part, "access": True, **({"contents": contents} if contents else {})}
    opened = SubTask(id=f"s0_open_{which}", description=f"open {container} ({part}) {why}",
                     method=SkillMethod.PRIMITIVE, primitive="pull", params=params,
                     reward=RewardSpec(terms=[RewardTerm(kind="distance", a="ee", b=container, weight=0.5),
                                              RewardTerm(kind="action_penalty", weight=0.01)]))
    shut = SubTask(id=f"s9_close_{which}", description=f"close {container} again", method=SkillMethod.PRIMITIVE,
                   primitive="push", params=params,
                   reward=RewardSpec(terms=[RewardTerm(kind="action_penalty", weight=0.01)]),
                   success=SuccessSpec(predicates=[PredicateCall(name="joint_closed", args={
                       "object": container, "label": part, "max_fraction": 0.1})]))
    return opened, shut


def plan_from_kb(task_id: str, hazard_class: str, bindings: dict[str, str], *, spec: SceneSpec | None = None,
                 source: str = "ground_truth", sac_actions: tuple[str, ...] | list[str] = ()) -> Plan:
    """A plan from the knowledge-base recipe of ``hazard_class``."""
    from anomalygen.knowledge.base import load_kb

    kb = load_kb()
    cls = kb.hazard_classes.get(hazard_class)
    if cls is None:
        raise ItemFailed(f"hazard class {hazard_class!r} is not in the knowledge base; no recipe to plan from")
    # the four role variables keep their old reading (a scene-less plan names them); any other one (the
    # lit burner of a composed class) must be bound, or the step would act on a '$source' that is nothing
    unbound = [v for v in cls.recipe_variable_names() if v not in bindings and v not in ROLE_VARIABLES]
    if unbound:
        raise ItemFailed(f"{hazard_class}: the recipe's {', '.join(unbound)} is not bound to a scene object")
    blocked = [step.action for step in cls.recipe if not plannable(step.action)]
    if blocked:
        raise ItemFailed(f"no skill for {blocked[0]} yet: {hazard_class}'s fix needs it")
    return plan_from_recipe(task_id, list(cls.recipe), list(cls.success), bindings, spec=spec, source=source,
                            sac_actions=sac_actions)


def plan_from_recipe(task_id: str, recipe: list, success: list[PredicateCall], bindings: dict[str, str], *,
                     spec: SceneSpec | None = None, source: str = "detected",
                     sac_actions: tuple[str, ...] | list[str] = ()) -> Plan:
    """A plan from recipe steps (``knowledge.models.RecipeStep``) and the success condition they serve:
    a class's recipe (:func:`plan_from_kb`), or the steps of one call of the skill-level env
    (``anomalygen.agents``), through the same sub-task, access and take-out machinery."""
    # A step goes to SAC when the recipe says so (``"method": "sac"``: a contact-rich part motion with a
    # shipped warm start, such as switch_off) or the user lists its action in ``plan.sac_actions``; it
    # keeps its reward spec either way.
    subtasks = []
    for i, step in enumerate(recipe):
        method = SkillMethod.SAC if step.method == "sac" or step.action in sac_actions else SkillMethod.PRIMITIVE
        if step.action == "switch_off":
            subtasks += switch_off_subtasks(i, dict(step.args), bindings, spec, list(success), method)
            continue
        st = step_to_subtask(i, step.action, dict(step.args), bindings, spec, list(success))
        subtasks.append(st.model_copy(update={"method": method}) if method != st.method else st)
    for step in recipe:
        # A container shut in the scene is opened before the object goes in (or comes out) and shut after.
        if step.action in ("place_inside", "take_out_of"):
            container = _resolve(step.args.get("container", "$container"), bindings)
            labels = closed_closures(spec, container)
            if labels:
                opened, shut = access_steps(container, labels)
                subtasks, after_shut = _checks_after_shutting(subtasks, container)
                shut = shut.model_copy(update={"success": SuccessSpec(predicates=[*shut.success.predicates, *after_shut])})
                subtasks = [opened, *subtasks, shut]
            break
    subtasks = _take_out_first(subtasks, recipe, bindings, spec)
    return Plan(task_id=task_id, source=source, engine=Engine.KNOWLEDGE, subtasks=subtasks,
                success=SuccessSpec(predicates=list(success)), bindings=dict(bindings))


def _checks_after_shutting(subtasks: list[SubTask], container: str) -> tuple[list[SubTask], list[PredicateCall]]:
    """The place step into a container that is opened for it checks only ``inside``; what holds only
    once the door is shut again (out of a child's reach: a safe stands open until then) moves to the
    shut step, where it can hold. Otherwise every such place fails its first check and is redone."""
    out, moved = [], []
    for st in subtasks:
        if st.primitive == "move_to" and st.params.get("region") == container:
            keep = [p for p in st.success.predicates if p.name == "inside"]
            moved += [p for p in st.success.predicates if p.name != "inside"]
            st = st.model_copy(update={"success": SuccessSpec(predicates=keep)})
        out.append(st)
    return out, moved


def _take_out_first(subtasks: list[SubTask], recipe: list, bindings: dict[str, str], spec: SceneSpec | None) -> list[SubTask]:
    """A recipe that starts with a pick, for an object lying in a container with doors or drawers
    (sour milk on a fridge shelf): the pick becomes take_out_of through the opening, with the part
    in front of the object opened before and shut after (a fridge door left open is a hazard too).

    The opening comes after the destination's (the cup cannot hold the object and a lid at once) and
    the shutting last, once the object is where it belongs. The scene spec says what lies inside what;
    that is geometry the robot perceives (the perceived spec keeps it), not the answer key.
    """
    if spec is None or not recipe or recipe[0].action != "pick":
        return subtasks
    obj = _resolve(recipe[0].args.get("object", "$hazard"), bindings)
    source = next((o.inside for o in spec.objects if o.name == obj), None)
    labels = sorted({js.label for o in spec.objects if o.name == source for js in o.joint_states
                     if js.label in (DRAWER, DOOR)}, key=CLOSURES.index)
    picks = [i for i, st in enumerate(subtasks) if st.primitive == "grasp"]
    if not labels or not picks:
        return subtasks
    out_of = PredicateCall(name="inside", args={"object": obj, "container": source}, negate=True)
    take = _handling_subtask(subtasks[picks[0]].id.replace("pick", "take_out_of"), "take_out_of", obj,
                             {"container": source}, {}, [out_of])
    opened, shut = access_steps(source, labels, contents=obj)
    return [*subtasks[:picks[0]], opened, take, *subtasks[picks[0] + 1:], shut]


def _bound(call: PredicateCall, bindings: dict[str, str]) -> PredicateCall:
    args = {k: _resolve(v, bindings) if isinstance(v, str) else v for k, v in call.args.items()}
    return call.model_copy(update={"args": args})


def merge_plans(plans: list[Plan]) -> Plan:
    """Several fixes in one plan, run in order. Each fix's variables are resolved to instance names
    first (two fixes bind ``$hazard`` to different objects); the merged plan keeps the first fix's
    bindings for display and succeeds when every fix's final condition holds."""
    if len(plans) == 1:
        return plans[0]
    subtasks: list[SubTask] = []
    success: list[PredicateCall] = []
    for i, plan in enumerate(plans, start=1):
        for st in plan.subtasks:
            spec = SuccessSpec(predicates=[_bound(c, plan.bindings) for c in st.success.predicates])
            subtasks.append(st.model_copy(update={"id": f"h{i}_{st.id}", "success": spec}))
        success += [_bound(c, plan.bindings) for c in plan.success.predicates]
    first = plans[0]
    return Plan(task_id=first.task_id, source=first.source, engine=first.engine, subtasks=subtasks,
                success=SuccessSpec(predicates=success), bindings=dict(first.bindings))
