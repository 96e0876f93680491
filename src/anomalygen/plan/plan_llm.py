"""The LLM planning engine: an LLM decomposes a hazard fix into sub-tasks and picks each one's method.

As in the paper, the model is shown the scene, the hazard and in-context examples of choosing a
method (a motion-planned primitive or SAC; CEM, which runs only on a legged body, is not
offered: household scenes carry a wheeled arm), and answers with sub-tasks, reward terms and success
predicates. Its reply is untrusted. The reply schema is small and flat (a tiny local model's grammar
must be able to write it) and advertises this scene's names as enums; a validator bound to the scene
then checks what JSON cannot: every object, region and joint exists, predicates are known and take
the arguments given, role variables are bound. A violation goes back to the model through the LLM
layer's repair loop, naming the bad value; a reply that never validates fails this item alone
(``LLMItemError``). The accepted reply becomes a ``schema.Plan`` of the same shape the knowledge
engine writes (role variables resolved in params and rewards, kept in predicates).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from functools import cache
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from anomalygen.errors import ItemFailed
from anomalygen.plan.llm_prompt import PRIMITIVES, messages
from anomalygen.schema import (
    Engine,
    JointState,
    PlacedObject,
    Plan,
    PredicateCall,
    RewardSpec,
    RewardTerm,
    SceneSpec,
    SkillMethod,
    SubTask,
    SuccessSpec,
)

REWARD_KINDS: tuple[str, ...] = RewardTerm.model_fields["kind"].annotation.__args__
#: Predicate arguments that must name one object (or a bound role variable).
OBJECT_ARGS = ("object", "a", "b")
#: Arguments that may also be '*' or category alternatives 'A|B' (see knowledge.predicates).
HOLDER_ARGS = ("container", "support")
NUMBER_ARGS = ("min", "max", "max_distance", "min_fraction", "max_fraction")
SURFACE_CENTRE = "surface_centre"
EE = "ee"
MAX_SUBTASKS = 8


# --------------------------------------------------------------------------- reply schema


KEEP_AS_WRITTEN = {"ee", "surface_centre"}  # reply words that are not object names


class ReplyParams(BaseModel):
    """Primitive parameters, flat: each primitive reads the ones it needs (see PRIMITIVES)."""

    model_config = ConfigDict(extra="forbid")

    object: str | None = Field(None, description="object acted on")
    region: str | None = Field(None, description="move_to/place_on/push_to destination, take_out_of source: object name or 'surface_centre'")
    joint: str | None = Field(None, description="full joint name for push/pull")
    target: float | None = Field(None, description="goal joint value for push/pull")
    part: str | None = Field(None, description="joint label (door, drawer, lid, knob, ...) instead of a joint name")
    lift: float | None = Field(None, description="grasp: metres to lift")
    release: bool | None = Field(None, description="move_to: let go at the destination")


class ReplyRewardTerm(BaseModel):
    model_config = ConfigDict(extra="forbid")

    kind: Literal[REWARD_KINDS]  # type: ignore[valid-type]
    weight: float = 1.0
    a: str | None = Field(None, description="'ee' (the gripper) or an object")
    b: str | None = Field(None, description="other object or region (distance, inside)")
    target: float | None = Field(None, description="joint value (joint) or height in metres (lifted)")
    joint: str | None = Field(None, description="joint name (joint)")


class ReplyPredicate(BaseModel):
    model_config = ConfigDict(extra="forbid")

    name: str = Field(description="a predicate from the list")
    args: dict[str, str | float] = Field(default_factory=dict)
    negate: bool = False


class ReplySubTask(BaseModel):
    model_config = ConfigDict(extra="forbid")

    id: str = Field(description="s<position>_<verb>, e.g. s1_pick")
    description: str = Field(min_length=1)
    # CEM plans a legged body's motion and runs only on the Gymnasium Ant: not offered here
    method: Literal["primitive", "sac"]
    primitive: str | None = Field(None, description="a primitive from the menu (required for method primitive)")
    params: ReplyParams = Field(default_factory=ReplyParams)
    reward: list[ReplyRewardTerm] = Field(default_factory=list)
    success: list[ReplyPredicate] = Field(default_factory=list, description="what holds after this step")


class TaskPlan(BaseModel):
    """What the model writes. Validated structurally here and semantically by ``reply_schema``'s subclass."""

    model_config = ConfigDict(extra="forbid")

    subtasks: list[ReplySubTask] = Field(min_length=1, max_length=MAX_SUBTASKS)
    success: list[ReplyPredicate] = Field(min_length=1, description="what holds once the fix is done")


# --------------------------------------------------------------------------- scene context


@dataclass
class PlanScene:
    """The names a plan may use, from one scene spec and its role bindings."""

    spec: SceneSpec
    bindings: dict[str, str]
    objects: dict[str, PlacedObject] = field(init=False)
    categories: set[str] = field(init=False)

    def __post_init__(self) -> None:
        self.objects = {o.name: o for o in self.spec.objects}
        self.categories = {o.asset.category for o in self.spec.objects}

    @property
    def joint_names(self) -> list[str]:
        return [j.name for o in self.spec.objects for j in o.joint_states]

    @property
    def labels(self) -> list[str]:
        return sorted({j.label for o in self.spec.objects for j in o.joint_states})

    def resolve(self, value: str) -> str:
        return self.bindings.get(value, value) if value.startswith("$") else value

    def joints_of(self, name: str) -> list[JointState]:
        obj = self.objects.get(self.resolve(name))
        return list(obj.joint_states) if obj is not None else []

    def joint(self, obj: str | None, name: str) -> JointState | None:
        """A joint by full name, or by its short name on ``obj`` (``drawer_slide`` for ``cabinet_0``)."""
        pool = self.joints_of(obj) if obj else [j for o in self.spec.objects for j in o.joint_states]
        for j in pool:
            if j.name == name or (obj and j.name == f"{self.resolve(obj)}/{name}"):
                return j
        return None


def _one_of(values: list[str]) -> str:
    shown = ", ".join(values[:40])
    return shown + (", ..." if len(values) > 40 else "")


class _Checker:
    """Collects every semantic problem of a reply (all at once, so one repair can fix them all)."""

    def __init__(self, scene: PlanScene):
        self.scene = scene
        self.problems: list[str] = []

    def bad(self, where: str, text: str) -> None:
        self.problems.append(f"{where}: {text}")

    def variable(self, where: str, value: str) -> bool:
        if value.startswith("$") and value not in self.scene.bindings:
            bound = ", ".join(sorted(self.scene.bindings)) or "none"
            self.bad(where, f"role variable {value} is not bound (bound: {bound})")
            return False
        return True

    def instance(self, where: str, value: str) -> bool:
        """An object name or a bound role variable."""
        if not self.variable(where, value):
            return False
        if self.scene.resolve(value) not in self.scene.objects:
            self.bad(where, f"'{value}' is not an object in the scene (objects: {_one_of(sorted(self.scene.objects))})")
            return False
        return True

    def place(self, where: str, value: str, *, ee_ok: bool) -> bool:
        """Reward references: 'ee', an object, 'object:link', or a role variable."""
        if value == EE:
            if not ee_ok:
                self.bad(where, "'ee' is the gripper, not an object or region")
            return ee_ok
        return self.instance(where, value.split(":", 1)[0] if not value.startswith("$") else value)

    # ------------------------------------------------------------------ parts of a reply
    def params(self, where: str, st: ReplySubTask) -> None:
        p = st.params
        if st.method == SkillMethod.PRIMITIVE:
            if not st.primitive:
                self.bad(where, f"method primitive needs a primitive (one of {', '.join(PRIMITIVES)})")
            needs = PRIMITIVES.get(st.primitive or "", ("",))[0]
            if "object" in needs and not p.object:
                self.bad(where, f"primitive {st.primitive} needs params.object")
            if "region" in needs and not p.region:
                self.bad(where, f"primitive {st.primitive} needs params.region")
            if "joint or part" in needs and not (p.joint or p.part):
                self.bad(where, f"primitive {st.primitive} needs params.joint or params.part")
        if st.primitive is not None and st.primitive not in PRIMITIVES:
            self.bad(where, f"unknown primitive '{st.primitive}' (known: {', '.join(PRIMITIVES)})")
        obj_ok = p.object is not None and self.instance(f"{where}.params.object", p.object)
        if p.region is not None and p.region != SURFACE_CENTRE:
            self.instance(f"{where}.params.region", p.region.split(":", 1)[0] if not p.region.startswith("$") else p.region)
        if p.joint is not None:
            js = self.scene.joint(p.object if obj_ok else None, p.joint)
            if js is None:
                names = [j.name for j in self.scene.joints_of(p.object)] if obj_ok else self.scene.joint_names
                owner = f"object '{p.object}'" if obj_ok else "the scene"
                self.bad(f"{where}.params.joint", f"'{p.joint}' is not a joint of {owner} (joints: {_one_of(names) or 'none'})")
            elif p.target is not None:
                lo, hi = sorted(js.range)
                slack = 0.05 * max(hi - lo, 1e-6)
                if not lo - slack <= p.target <= hi + slack:
                    self.bad(f"{where}.params.target", f"{p.target} is outside the range [{lo}, {hi}] of joint {js.name}")
        if p.part is not None and obj_ok:
            labels = sorted({j.label for j in self.scene.joints_of(p.object)})
            if p.part not in labels:
                self.bad(f"{where}.params.part", f"object '{p.object}' has no part labelled '{p.part}' (parts: {', '.join(labels) or 'none'})")
        if p.lift is not None and not 0.0 <= p.lift <= 0.5:
            self.bad(f"{where}.params.lift", f"{p.lift} m is not a lift height between 0 and 0.5")

    def reward(self, where: str, st: ReplySubTask) -> None:
        if st.method != SkillMethod.PRIMITIVE and not any(t.kind != "action_penalty" for t in st.reward):
            self.bad(where, f"method {st.method} learns from its reward: give at least one reward term besides action_penalty")
        for k, t in enumerate(st.reward):
            w = f"{where}.reward[{k}]"
            needs = {"distance": ("a", "b"), "inside": ("a", "b"), "lifted": ("a", "target"),
                     "joint": ("joint", "target"), "upright": ("a",), "action_penalty": ()}[t.kind]
            for name in needs:
                if getattr(t, name) is None:
                    self.bad(w, f"a {t.kind} term needs '{name}'")
            if t.a is not None:
                self.place(f"{w}.a", t.a, ee_ok=t.kind != "upright")
            if t.b is not None:
                self.place(f"{w}.b", t.b, ee_ok=t.kind == "distance")
            if t.joint is not None and self.scene.joint(None, t.joint) is None:
                self.bad(f"{w}.joint", f"'{t.joint}' is not a joint in the scene (joints: {_one_of(self.scene.joint_names) or 'none'})")

    def predicate(self, where: str, call: ReplyPredicate) -> None:
        from anomalygen.knowledge.models import PROPERTIES
        from anomalygen.knowledge.predicates import PREDICATES

        spec = PREDICATES.get(call.name)
        if spec is None:
            self.bad(where, f"unknown predicate '{call.name}' (known: {', '.join(sorted(PREDICATES))})")
            return
        where = f"{where} {call.name}"
        for arg in call.args:
            if arg not in spec.args:
                self.bad(where, f"takes no argument '{arg}' (arguments: {', '.join(spec.args)})")
        for arg in _required_args(call.name):
            if arg not in call.args:
                self.bad(where, f"needs argument '{arg}'")
        if call.name == "height_above_floor" and not ({"min", "max"} & call.args.keys()):
            self.bad(where, "needs 'min' and/or 'max'")
        for arg, value in call.args.items():
            text = str(value)
            if arg in NUMBER_ARGS:
                try:
                    float(value)  # type: ignore[arg-type]
                except (TypeError, ValueError):
                    self.bad(f"{where}.{arg}", f"must be a number, got {value!r}")
            elif arg in OBJECT_ARGS:
                self.instance(f"{where}.{arg}", text)
            elif arg in HOLDER_ARGS and text != "*":
                if text.startswith("$"):
                    self.instance(f"{where}.{arg}", text)
                else:
                    unknown = [a for a in _alternatives(text) if a not in self.scene.objects and a not in self.scene.categories]
                    if unknown or not _alternatives(text):
                        self.bad(f"{where}.{arg}", f"'{text}' names no object or category in the scene "
                                 f"(objects: {_one_of(sorted(self.scene.objects))})")
            elif arg == "property":
                unknown = [a for a in _alternatives(text) if a not in PROPERTIES]
                if unknown:
                    self.bad(f"{where}.property", f"unknown property '{'|'.join(unknown)}' (known: {', '.join(PROPERTIES)})")
            elif arg == "label" and text != "*":
                obj = call.args.get("object")
                labels = {j.label for j in self.scene.joints_of(str(obj))} if obj is not None else set(self.scene.labels)
                if not labels & set(_alternatives(text)):
                    self.bad(f"{where}.label", f"no joint labelled '{text}' on {obj or 'any object'} "
                             f"(labels: {', '.join(sorted(labels)) or 'none'})")

    def plan(self, reply: TaskPlan) -> list[str]:
        seen: set[str] = set()
        for i, st in enumerate(reply.subtasks):
            where = f"subtasks[{i}] ({st.id})"
            if not re.fullmatch(r"[A-Za-z0-9_\-]{1,40}", st.id):
                self.bad(where, "id must be a short word like s1_pick (letters, digits, underscores)")
            if st.id in seen:
                self.bad(where, f"duplicate sub-task id '{st.id}'")
            seen.add(st.id)
            self.params(where, st)
            self.reward(where, st)
            for k, call in enumerate(st.success):
                self.predicate(f"{where}.success[{k}]", call)
        for k, call in enumerate(reply.success):
            self.predicate(f"success[{k}]", call)
        return self.problems


def _alternatives(value: str) -> list[str]:
    return [v.strip() for v in value.split("|") if v.strip()]


@cache
def _required_args(name: str) -> tuple[str, ...]:
    """Arguments a predicate cannot do without (the rest have defaults in knowledge.predicates)."""
    from anomalygen.knowledge.predicates import PREDICATES

    args = PREDICATES[name].args
    return tuple(a for a in ("object", "a", "b", "room", "property", "category") if a in args)


def check_reply(reply: TaskPlan, scene: PlanScene) -> list[str]:
    """Every semantic problem of ``reply`` in ``scene`` (empty when it can be turned into a Plan)."""
    return _Checker(scene).plan(reply)


def reply_schema(scene: PlanScene) -> type[TaskPlan]:
    """``TaskPlan`` bound to one scene: names as schema enums, and a validator that rejects the rest.

    Why a validator and not only enums: a rejected value must go back to the model *by name* ("'fridge'
    is not an object in the scene"), which a failed enum match does not say.
    """

    names = sorted(scene.objects) + sorted(scene.bindings)
    hints = {
        ("ReplyParams", "object"): names,
        ("ReplyParams", "joint"): scene.joint_names,
        ("ReplyParams", "part"): scene.labels,
        ("ReplySubTask", "primitive"): list(PRIMITIVES),
    }

    class TaskPlanInScene(TaskPlan):
        @model_validator(mode="before")
        @classmethod
        def _grounded(cls, data: Any) -> Any:
            return ground_reply_names(data, scene)

        @model_validator(mode="after")
        def _in_scene(self) -> TaskPlanInScene:
            problems = check_reply(self, scene)
            if problems:
                raise ValueError("; ".join(problems))
            return self

        @classmethod
        def model_json_schema(cls, *args: Any, **kwargs: Any) -> dict[str, Any]:
            schema = super().model_json_schema(*args, **kwargs)
            for (model, prop), values in hints.items():
                node = schema.get("$defs", {}).get(model, {}).get("properties", {}).get(prop)
                if node is None or not values:
                    continue
                typed = {"type": "string", "enum": sorted(set(values))}
                if "anyOf" in node:
                    node["anyOf"] = [typed if alt.get("type") == "string" else alt for alt in node["anyOf"]]
                else:
                    node.update(typed)
            return schema

    TaskPlanInScene.__name__ = TaskPlanInScene.__qualname__ = "TaskPlan"
    return TaskPlanInScene


def ground_reply_names(data: Any, scene: PlanScene) -> Any:
    """Object names the model wrote loosely ("the fridge", "Kettle") resolved to the scene's instances
    by the one grounding module (spelling, aliases, retrieval), before validation. A name that even
    retrieval cannot place is left as written, so the scene check names it and the repair turn asks
    again."""
    if not isinstance(data, dict) or not isinstance(data.get("subtasks"), list):
        return data
    from anomalygen.knowledge.grounding import shared_grounder

    vocab = shared_grounder().instances([(o.name, o.asset.category) for o in scene.spec.objects])

    def grounded(value: Any, where: str) -> Any:
        if not isinstance(value, str) or value in scene.objects or value.startswith("$") or value in KEEP_AS_WRITTEN:
            return value
        head, sep, tail = value.partition(":")
        match = vocab.ground(head, where).grounded
        return f"{match}{sep}{tail}" if match is not None else value

    for st in data["subtasks"]:
        if not isinstance(st, dict):
            continue
        params = st.get("params")
        if isinstance(params, dict):
            for key in ("object", "region"):
                if key in params:
                    params[key] = grounded(params[key], f"params.{key}")
        for term in st.get("reward") or []:
            if isinstance(term, dict):
                for key in ("a", "b"):
                    if key in term:
                        term[key] = grounded(term[key], f"reward.{key}")
    return data


# --------------------------------------------------------------------------- prompt


# --------------------------------------------------------------------------- reply -> Plan


def _args(call: ReplyPredicate) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in call.args.items():
        if k in NUMBER_ARGS and isinstance(v, str):
            v = float(v)
        out[k] = v
    return out


def to_plan(reply: TaskPlan, scene: PlanScene, task_id: str, *, source: str = "ground_truth") -> Plan:
    """An accepted reply as a Plan: role variables resolved in params and rewards, kept in predicates."""
    subtasks = []
    for st in reply.subtasks:
        params: dict[str, Any] = {}
        for key, value in st.params.model_dump(exclude_none=True).items():
            params[key] = scene.resolve(value) if isinstance(value, str) else value
        if "joint" in params:
            js = scene.joint(params.get("object"), params["joint"])
            params["joint"] = js.name if js is not None else params["joint"]
        terms = []
        for t in st.reward:
            data = t.model_dump(exclude_none=True)
            for ref in ("a", "b"):
                if ref in data:
                    base, _, link = data[ref].partition(":")
                    data[ref] = scene.resolve(base) + (f":{link}" if link else "")
            terms.append(RewardTerm.model_validate(data))
        subtasks.append(
            SubTask(
                id=st.id, description=st.description, method=SkillMethod(st.method), primitive=st.primitive, params=params,
                reward=RewardSpec(terms=terms) if terms else None,
                success=SuccessSpec(predicates=[PredicateCall(name=c.name, args=_args(c), negate=c.negate) for c in st.success]),
            )
        )
    final = [PredicateCall(name=c.name, args=_args(c), negate=c.negate) for c in reply.success]
    return Plan(task_id=task_id, source=source, engine=Engine.LLM, subtasks=subtasks,
                success=SuccessSpec(predicates=final), bindings=dict(scene.bindings))


def plan_from_llm(
    task_id: str,
    hazard_class: str,
    bindings: dict[str, str],
    *,
    spec: SceneSpec,
    client,
    hazard: str = "",
    source: str = "ground_truth",
    kb=None,
    temperature: float | None = 0.0,
    seed: int | None = 0,
) -> Plan:
    """Ask ``client`` for a plan of this scene's fix; raises ItemFailed/LLMItemError with one line."""
    if kb is None:
        from anomalygen.knowledge.base import load_kb

        kb = load_kb()
    known = {o.name for o in spec.objects}
    stray = {v: n for v, n in bindings.items() if n not in known}
    if stray:
        var, name = sorted(stray.items())[0]
        raise ItemFailed(f"{var} is bound to '{name}', which is not an object in scene {spec.scene_id}")
    scene = PlanScene(spec, dict(bindings))
    schema = reply_schema(scene)
    reply = client.complete(messages(spec, hazard_class, hazard, scene.bindings, kb), schema=schema,
                            temperature=temperature, seed=seed)
    return to_plan(reply, scene, task_id, source=source)
