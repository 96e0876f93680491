"""The skill-level env's actions: one call of the robot's skill vocabulary, as text or structured.

Why calls and not joint torques: an agent that detects a hazard should be judged on what it chooses to
do about it (put the knife in the drawer, switch the stove off), with the robot's own skills doing the
motion, as our pipeline does. A call names a skill and the scene objects it acts on::

    pick_place(knife_0, drawer_0)         switch_off(stove_0, knob_2)       close(fridge_0, door)
    move_away(power_strip_0, sink_0)      turn_inward(pot_0)                done

Text or structured (``{"skill": "pick_place", "args": {"object": "knife_0", "destination":
"drawer_0"}}``, positional args as a list, or the args flat beside ``skill``) both become a
:class:`Call`. :func:`validate_call` checks it against what the robot perceives (:class:`SceneView`: the
objects, which of them can be moved, their parts and which have an inside), fills the defaults, and
raises :class:`CallError` with the reason: the env puts that reason in ``info["error"]`` and never
raises. How a valid call becomes sub-tasks is ``agents/expand.py``.
"""

from __future__ import annotations

import difflib
import re
from collections.abc import Mapping
from dataclasses import dataclass

from pydantic import Field

from anomalygen.errors import AnomalygenError
from anomalygen.schema import Strict, part_labels

DONE = "done"
WAIT = "wait"
FIX = "fix"
WAIT_STEPS = 25  # control steps a bare ``wait`` lets the scene settle (as the learn stage does after a plan)
MAX_WAIT_STEPS = 500  # a wait longer than 5 s of simulated time is a mistake, not a plan
MOVE_AWAY_M = 0.6  # default distance of move_away (the knowledge base's electrical-from-water fix)
QUOTE = 400  # characters of an unreadable action quoted back in its error


class CallError(AnomalygenError, ValueError):
    """An action that is no valid call in this scene; the message says why (it goes to ``info["error"]``)."""


class Call(Strict):
    """One call: a skill of :data:`VOCABULARY` and its arguments by name."""

    skill: str
    args: dict[str, str | float] = Field(default_factory=dict)

    def text(self) -> str:
        """``pick_place(knife_0, drawer_0)``: arguments by position while none is skipped, the rest as key=value."""
        spec = VOCABULARY.get(self.skill)
        order = [p.name for p in spec.params] if spec is not None else []
        pos: list[str] = []
        for name in order:
            if name not in self.args:
                break
            pos.append(_show(self.args[name]))
        kw = [f"{k}={_show(v)}" for k, v in self.args.items() if k not in order[:len(pos)]]
        inner = ", ".join(pos + kw)
        return f"{self.skill}({inner})" if inner else self.skill

    def __str__(self) -> str:
        return self.text()


def _show(v) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


@dataclass(frozen=True)
class Param:
    """One argument. ``kind``: ``object`` (any scene object), ``movable`` (one the robot can carry or
    slide: not fixed furniture), ``part`` (a part of the call's object, by label or name), ``number``,
    ``how`` (in or on), ``class`` (a hazard class of the knowledge base)."""

    name: str
    kind: str
    required: bool = True
    doc: str = ""


@dataclass(frozen=True)
class SkillCall:
    """One entry of the vocabulary."""

    name: str
    params: tuple[Param, ...]
    doc: str
    roles: bool = False  # takes role=object keywords beyond its params (fix)

    def param(self, name: str) -> Param:
        return next(p for p in self.params if p.name == name)

    def signature(self) -> str:
        parts = [p.name if p.required else f"{p.name}=..." for p in self.params]
        if self.roles:
            parts.append("role=object ...")
        return f"{self.name}({', '.join(parts)})" if parts else self.name


_OBJ = Param("object", "movable", doc="the object to move")
VOCABULARY: dict[str, SkillCall] = {c.name: c for c in (
    SkillCall("pick_place", (_OBJ, Param("destination", "object", doc="where it goes"),
                             Param("how", "how", False, "in (its inside, opened and shut again as needed) or on; "
                                   "default: in when the destination has an inside")),
              "pick the object up and put it in or on the destination"),
    SkillCall("take_out", (_OBJ, Param("container", "object", doc="what it is in"),
                           Param("destination", "object", doc="the surface it goes on")),
              "take the object out of the container it is in (an appliance, a sink) and set it on the destination"),
    SkillCall("open", (Param("object", "object"), Param("part", "part", False, "door, drawer, lid, window, ... or a "
                                                        "part's name; default: every closure"),
                       Param("fraction", "number", False, "how far, 0..1")),
              "open a part of the object"),
    SkillCall("close", (Param("object", "object"), Param("part", "part", False, "door, drawer, lid, window, gate, "
                                                         "... or a part's name; default: every closure")),
              "close a part of the object (every part with that label, most open first)"),
    SkillCall("switch_off", (Param("object", "object"), Param("part", "part", False, "knob, switch, tap or a part's "
                                                              "name (knob_2); default: every control that is on")),
              "switch the object off"),
    SkillCall("move_from_edge", (_OBJ,), "set the object down well back from the edge of its surface"),
    SkillCall("move_away", (_OBJ, Param("from", "object", doc="what it must be away from"),
                            Param("distance", "number", False, f"metres, default {MOVE_AWAY_M}")),
              "carry the object at least that far from the other object"),
    SkillCall("take_off", (_OBJ, Param("support", "object", False, "default: the nearest safe surface")),
              "lift the object off what it lies on (a hob, a stair, a crib) onto a safe surface"),
    SkillCall("turn_inward", (_OBJ,), "turn a pan or pot so its handle points back over the hob"),
    SkillCall("push_to", (_OBJ, Param("destination", "object", doc="what it should stand beside")),
              "slide the object over the floor until it stands beside the destination"),
    SkillCall(FIX, (Param("object", "object", doc="the object at fault"), Param("hazard_class", "class")),
              "fix a hazard the knowledge base knows, by its recipe: give the roles you choose as "
              "role=object (container=drawer_0, support=table_0); the others are chosen from the scene",
              roles=True),
    SkillCall(WAIT, (Param("steps", "number", False, f"control steps, default {WAIT_STEPS}"),),
              "let the scene settle"),
    SkillCall(DONE, (), "end the episode: the referee judges the scene as it is left"),
)}


# ----------------------------------------------------------------------------------------- parsing

_CALL = re.compile(r"^\s*([A-Za-z_][\w.]*)\s*(?:\((.*)\))?\s*;?\s*$", re.S)
_TOKEN = re.compile(r"""\s*(?:(\w+)\s*=\s*)?("(?:[^"\\]|\\.)*"|'(?:[^'\\]|\\.)*'|[^,()]+?)\s*(?:,|$)""")


def parse_call(action) -> Call:
    """Text (``pick_place(knife_0, drawer_0)``), a dict, or a Call -> a Call (arguments not checked
    yet: :func:`validate_call`). CallError when it is none of those."""
    if isinstance(action, Call):
        return action
    if isinstance(action, Mapping):
        return _from_mapping(action)
    if isinstance(action, bytes):
        action = action.decode("utf-8", "replace")
    if not isinstance(action, str):
        raise CallError(f"an action is a call as text or a dict, not {type(action).__name__}")
    m = _CALL.match(action.strip().strip("`"))
    if m is None:
        raise CallError(f"not a call: {action[:QUOTE]!r} (write it as skill(arg, ...), e.g. pick_place(knife_0, drawer_0))")
    name, inner = m.group(1), (m.group(2) or "").strip()
    positional: list[str] = []
    named: dict[str, str] = {}
    pos = 0
    while pos < len(inner):
        t = _TOKEN.match(inner, pos)
        if t is None or t.end() == pos:
            raise CallError(f"cannot read the arguments of {action[:QUOTE]!r}")
        key, value = t.group(1), _unquote(t.group(2))
        if key:
            named[key] = value
        elif named:
            raise CallError(f"{name}: a positional argument after a named one in {action[:QUOTE]!r}")
        else:
            positional.append(value)
        pos = t.end()
    return _assemble(name, positional, named)


def _unquote(v: str) -> str:
    v = v.strip()
    return v[1:-1] if len(v) >= 2 and v[0] == v[-1] and v[0] in "'\"" else v


def _from_mapping(d: Mapping) -> Call:
    name = d.get("skill", d.get("name"))
    if not isinstance(name, str):
        raise CallError("a structured call needs 'skill': the skill's name")
    args = d.get("args", {k: v for k, v in d.items() if k not in ("skill", "name")})
    if isinstance(args, list | tuple):
        return _assemble(name, [str(a) for a in args], {})
    if not isinstance(args, Mapping):
        raise CallError(f"{name}: 'args' is a list or a dict")
    return _assemble(name, [], {str(k): v for k, v in args.items() if v is not None})


def _assemble(name: str, positional: list[str], named: dict) -> Call:
    spec = VOCABULARY.get(name)
    if spec is None:
        close = difflib.get_close_matches(name, list(VOCABULARY), n=1)
        hint = f" (did you mean {close[0]}?)" if close else ""
        raise CallError(f"unknown skill {name!r}{hint}; the skills: {', '.join(VOCABULARY)}")
    if len(positional) > len(spec.params):
        raise CallError(f"{name} takes {len(spec.params)} arguments, not {len(positional)}: {spec.signature()}")
    args: dict = dict(zip((p.name for p in spec.params), positional, strict=False))
    for k, v in named.items():
        if k in args:
            raise CallError(f"{name}: {k} given twice")
        args[k] = v
    return Call(skill=name, args={k: v if isinstance(v, int | float) and not isinstance(v, bool) else str(v)
                                  for k, v in args.items()})


# ----------------------------------------------------------------------------------------- checking

@dataclass(frozen=True)
class PartView:
    name: str  # the part's name: its joint's name after the object's, less "_joint" (knob_2)
    label: str  # door, drawer, lid, knob, ...


@dataclass(frozen=True)
class ObjectView:
    name: str
    kind: str
    movable: bool
    container: bool  # it has an inside (a declared cavity)
    parts: tuple[PartView, ...] = ()


@dataclass(frozen=True)
class SceneView:
    """What checking a call reads: the perceived objects (the env's ``objects`` observation)."""

    objects: dict[str, ObjectView]

    @classmethod
    def from_objects(cls, objects) -> SceneView:
        """From the ``objects`` observation (dicts with name, kind, movable, container, parts)."""
        return cls({o["name"]: ObjectView(o["name"], o["kind"], bool(o["movable"]), bool(o["container"]),
                                          tuple(PartView(p["name"], p["label"]) for p in o["parts"]))
                    for o in objects})


def part_name(joint: str) -> str:
    """``stove_0/knob_2_joint`` -> ``knob_2``: how calls name one part."""
    return joint.split("/", 1)[-1].removesuffix("_joint")


def validate_call(call: Call, view: SceneView, kb) -> Call:
    """The call with its arguments checked against the scene and defaults filled; CallError if not valid."""
    spec = VOCABULARY[call.skill]
    args = dict(call.args)
    for p in spec.params:
        if p.required and p.name not in args:
            raise CallError(f"{call.skill} needs {p.name}: {spec.signature()}")
    known = {p.name for p in spec.params}
    roles = {k: v for k, v in args.items() if k not in known}
    if roles and not spec.roles:
        raise CallError(f"{call.skill} takes no {', '.join(sorted(roles))}: {spec.signature()}")
    for p in spec.params:
        if p.name in args:
            args[p.name] = _check(call.skill, p, args[p.name], args, view, kb)
    for role, name in roles.items():
        _object(call.skill, role, name, view)
    if call.skill == "pick_place":
        if args["destination"] == args["object"]:
            raise CallError("pick_place: the destination is the object itself")
        args.setdefault("how", "in" if view.objects[args["destination"]].container else "on")
        if args["how"] == "in" and not view.objects[args["destination"]].container:
            raise CallError(f"pick_place: {args['destination']} has no inside to put things in; use how=on")
    if call.skill in ("open", "close") and not _parts(view.objects[args["object"]], part_labels.is_closure):
        raise CallError(f"{call.skill}: {args['object']} has nothing that opens or closes")
    if call.skill == "switch_off" and not _parts(view.objects[args["object"]], part_labels.is_switch):
        raise CallError(f"switch_off: {args['object']} has no knob, switch or tap")
    if call.skill == FIX:
        _check_roles(args, roles, kb)
    return Call(skill=call.skill, args=args)


def _check(skill: str, p: Param, value, args: dict, view: SceneView, kb):
    if p.kind in ("object", "movable"):
        obj = _object(skill, p.name, value, view)
        if p.kind == "movable" and not obj.movable:
            raise CallError(f"{skill}: {obj.name} is fixed in place; the robot cannot carry it")
        return obj.name
    if p.kind == "number":
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise CallError(f"{skill}: {p.name} is a number, not {value!r}") from None
        if skill == WAIT and not 1 <= number <= MAX_WAIT_STEPS:
            raise CallError(f"wait: steps is 1 to {MAX_WAIT_STEPS}")
        if p.name == "fraction" and not 0 < number <= 1:
            raise CallError(f"{skill}: fraction is more than 0 and at most 1")
        if p.name == "distance" and not 0 < number <= 5:
            raise CallError(f"{skill}: distance is more than 0 and at most 5 m")
        return number
    if p.kind == "how":
        if value not in ("in", "on"):
            raise CallError(f"{skill}: how is in or on, not {value!r}")
        return value
    if p.kind == "class":
        if value not in kb.hazard_classes:
            close = difflib.get_close_matches(str(value), list(kb.hazard_classes), n=1)
            raise CallError(f"{skill}: no hazard class {value!r}" + (f" (did you mean {close[0]}?)" if close else ""))
        return value
    if p.kind == "part":
        return _part(skill, view.objects[str(args["object"])], str(value))
    raise AssertionError(p.kind)  # pragma: no cover - the table's kinds are the ones above


def _object(skill: str, what: str, name, view: SceneView) -> ObjectView:
    obj = view.objects.get(str(name))
    if obj is None:
        close = difflib.get_close_matches(str(name), list(view.objects), n=1)
        hint = f" (closest: {close[0]})" if close else ""
        raise CallError(f"{skill}: {what} {name!r} is not an object in the scene{hint}")
    return obj


def _parts(obj: ObjectView, kind) -> list[PartView]:
    return [p for p in obj.parts if kind(p.label)]


def _part(skill: str, obj: ObjectView, value: str) -> str:
    """A label the object has (door, knob, 'door|drawer') or the name of one of its parts."""
    if any(p.name == value for p in obj.parts):
        return value
    labels = part_labels.alternatives(value)
    if labels and all(any(p.label == lab for p in obj.parts) for lab in labels):
        return value
    have = sorted({p.label for p in obj.parts} | {p.name for p in obj.parts})
    raise CallError(f"{skill}: {obj.name} has no part {value!r} (its parts: {', '.join(have) or 'none'})")


def _check_roles(args: dict, roles: dict, kb) -> None:
    hc = kb.hazard_classes[args["hazard_class"]]
    wanted = {v.lstrip("$") for v in [*hc.variable_names(), *hc.recipe_variable_names()]}
    bad = sorted(set(roles) - wanted)
    if bad:
        raise CallError(f"fix: {hc.id} has no role {', '.join(bad)} (its roles: {', '.join(sorted(wanted))})")


def vocabulary_text() -> str:
    """The vocabulary as a list for people and prompts: one line a skill."""
    return "\n".join(f"- {c.signature()}: {c.doc}" for c in VOCABULARY.values())
