"""A valid call -> the sub-tasks that carry it out, through the planner's own recipe machinery.

Why the planner's: our pipeline and an outside agent must share one executor. Each call is written as
knowledge-base recipe steps (``pick_place`` is ``pick`` then ``place_inside`` or ``place_on``) and
planned by :func:`~anomalygen.plan.planner.plan_from_recipe` — the same sub-tasks, the same opening and
shutting of a closed container around a place, the same take-out through a door — then run by the
learn stage's loop (``learn/execute.py``: retries, the SAC fallback). ``fix`` plans a knowledge-base
class's whole recipe (:func:`~anomalygen.plan.planner.plan_from_kb`) with the roles the agent chose,
the rest bound from the scene as the plan stage binds them (``plan/bind.py``).

Each call's sub-tasks check their own success (a retry follows a failed check): what the call means
(``pick_place(knife_0, drawer_0)``: the knife is inside the drawer), or with ``fix`` the class's own
success condition, as the planner checks it.
"""

from __future__ import annotations

from anomalygen.agents.vocabulary import FIX, MOVE_AWAY_M, Call, CallError
from anomalygen.errors import ItemFailed
from anomalygen.schema import (
    CLOSURE_LABELS,
    LID_LABELS,
    SWITCH_LABELS,
    Plan,
    PredicateCall,
    SceneGraph,
    SceneSpec,
    part_labels,
)

EDGE_CLEAR_M = 0.15  # move_from_edge's check: as the knowledge base's edge classes check it
AWAY_CHECK_M = 0.3  # move_away's check: no longer within this of the other object (the classes' own)
BESIDE_M = 0.5  # push_to's check: within this of the destination
OPEN_CHECK = 0.12  # open's check without a fraction: at least this far open (ventilate_room's check)


def _p(name: str, negate: bool = False, **args) -> PredicateCall:
    return PredicateCall(name=name, args=args, negate=negate)


def plan_for_call(call: Call, graph: SceneGraph, spec: SceneSpec, kb, task_id: str, *,
                  sac_actions=()) -> Plan:
    """The plan of one validated call on the scene as it stands (``spec`` with today's joint values);
    CallError when the planner cannot plan it (nothing in the scene can play a role of a fix)."""
    from anomalygen.knowledge.models import RecipeStep
    from anomalygen.plan.planner import plan_from_kb, plan_from_recipe

    try:
        if call.skill == FIX:
            return plan_from_kb(task_id, str(call.args["hazard_class"]), _fix_bindings(call, graph, kb), spec=spec,
                                source="detected", sac_actions=sac_actions)
        steps, success, bindings = _recipe(call, spec)
        recipe = [RecipeStep(action=a, args=args, method=method) for a, args, method in steps]
        return plan_from_recipe(task_id, recipe, success, bindings, spec=spec, source="detected",
                                sac_actions=sac_actions)
    except ItemFailed as exc:
        raise CallError(f"{call.text()}: {exc}") from None


def _fix_bindings(call: Call, graph: SceneGraph, kb) -> dict[str, str]:
    from anomalygen.plan.bind import bind_fix

    hc = kb.hazard_classes[str(call.args["hazard_class"])]
    given = {f"${k}": str(v) for k, v in call.args.items() if k not in ("object", "hazard_class")}
    return bind_fix(hc, str(call.args["object"]), graph, kb, given=given)


def _recipe(call: Call, spec: SceneSpec):
    """(steps as (action, args, method), success, bindings) of a skill call."""
    a = call.args
    obj = str(a["object"])
    h = {"$hazard": obj}
    s = call.skill
    if s == "pick_place":
        dest = str(a["destination"])
        if a["how"] == "in":
            return ([("pick", {"object": "$hazard"}, "primitive"),
                     ("place_inside", {"object": "$hazard", "container": "$container"}, "primitive")],
                    [_p("inside", object="$hazard", container="$container")], {**h, "$container": dest})
        return ([("pick", {"object": "$hazard"}, "primitive"),
                 ("place_on", {"object": "$hazard", "support": "$support"}, "primitive")],
                [_p("on", object="$hazard", support="$support")], {**h, "$support": dest})
    if s == "take_out":
        return ([("take_out_of", {"object": "$hazard", "container": "$target"}, "primitive"),
                 ("place_on", {"object": "$hazard", "support": "$support"}, "primitive")],
                [_p("inside", True, object="$hazard", container="$target"), _p("on", object="$hazard", support="$support")],
                {**h, "$target": str(a["container"]), "$support": str(a["destination"])})
    if s in ("open", "close"):
        return _closure(call, spec)
    if s == "switch_off":
        args = {"object": "$target", "label": part_labels.any_of(SWITCH_LABELS)}
        success = [_p("is_on", True, object="$target")]
        if "part" in a:
            label, joint = _label_of(spec, obj, str(a["part"]))
            args["label"] = label
            if joint is not None:
                args["joint"], success = joint, []  # one control: the others may stay on
        return [("switch_off", args, "sac")], success, {"$target": obj}
    if s == "move_from_edge":
        return ([("move_away_from_edge", {"object": "$hazard"}, "primitive")],
                [_p("near_edge", True, object="$hazard", max_distance=EDGE_CLEAR_M), _p("on_floor", True, object="$hazard")], h)
    if s == "move_away":
        dist = float(a.get("distance", MOVE_AWAY_M))
        return ([("move_away", {"object": "$hazard", "from": "$other", "distance": f"{dist:g}"}, "primitive")],
                [_p("near", True, a="$hazard", b="$other", max_distance=min(AWAY_CHECK_M, dist))],
                {**h, "$other": str(a["from"])})
    if s == "take_off":
        if "support" in a:
            return ([("take_off", {"object": "$hazard", "support": "$support"}, "primitive")],
                    [_p("on", object="$hazard", support="$support")], {**h, "$support": str(a["support"])})
        return [("take_off", {"object": "$hazard"}, "primitive")], [], h
    if s == "turn_inward":
        return ([("rotate_inward", {"object": "$hazard"}, "primitive")],
                [_p("has_state", True, object="$hazard", state="handle_out")], h)
    if s == "push_to":
        return ([("push_to", {"object": "$hazard", "support": "$support"}, "primitive")],
                [_p("near", a="$hazard", b="$support", max_distance=BESIDE_M)], {**h, "$support": str(a["destination"])})
    raise CallError(f"{s} is not a skill that moves anything")  # wait and done are the env's own


def _closure(call: Call, spec: SceneSpec):
    """open / close: a lid or flap as the lid skills do it, any other closure as a joint step."""
    obj = str(call.args["object"])
    opening = call.skill == "open"
    part = call.args.get("part")
    label, joint = _label_of(spec, obj, str(part)) if part else (part_labels.any_of(CLOSURE_LABELS), None)
    if joint is not None:  # one named part: every part with its label is driven, most open first
        label = next(js.label for o in spec.objects if o.name == obj for js in o.joint_states if js.name == joint)
    b = {"$target": obj}
    if set(part_labels.alternatives(label)) <= set(LID_LABELS):
        action = "open_lid" if opening else "close_lid"
        check = _p("joint_open", object="$target", label=label, min_fraction=OPEN_CHECK) if opening else \
            _p("joint_closed", object="$target", label=label, max_fraction=part_labels.CLOSED_TOL)
        return [(action, {"object": "$target"}, "primitive")], [check], b
    if opening:
        args = {"object": "$target", "label": label}
        least = OPEN_CHECK
        if "fraction" in call.args:
            args["fraction"] = f"{float(call.args['fraction']):g}"
            least = min(OPEN_CHECK, 0.6 * float(call.args["fraction"]))
        return [("open_joint", args, "primitive")], [_p("joint_open", object="$target", label=label, min_fraction=least)], b
    return ([("close_joint", {"object": "$target", "label": label}, "primitive")],
            [_p("joint_closed", object="$target", label=label, max_fraction=part_labels.CLOSED_TOL)], b)


def _label_of(spec: SceneSpec, obj: str, part: str) -> tuple[str, str | None]:
    """(label, joint name or None) of a call's part: a label as given, or the label of the named part."""
    from anomalygen.agents.vocabulary import part_name

    for o in spec.objects:
        if o.name == obj:
            for js in o.joint_states:
                if part in (part_name(js.name), js.name.split("/", 1)[-1]):
                    return js.label, js.name
    return part, None
