"""The LLM planner's prompt: the system prompt, the primitive menu, the scene and hazard as text, and
the in-context examples (``data/prompts/plan_examples.json``), rendered with the same code as a real
scene. Kept apart from :mod:`~anomalygen.plan.plan_llm`, which validates the reply and turns it into a
Plan, so the words the model sees can change without touching the checks.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from functools import cache
from importlib import resources

from anomalygen.schema import JointState, ObjectRole, PlacedObject, SceneSpec

#: The registered scripted skills' actions (skills/scripted/actions.py) and the params each one needs.
PRIMITIVES: dict[str, tuple[str, str]] = {
    "grasp": ("object", "suction-grasp the object and lift it `lift` metres (default 0.12)"),
    "approach": ("object", "bring the gripper next to the object"),
    "move_to": ("object, region", "carry the held object into or onto `region` (an object, or 'surface_centre' "
                "of its own surface); `release` true lets go"),
    "release": ("", "let go of what is held"),
    "push": ("object, joint or part", "press a part towards joint value `target` (its closed value closes it)"),
    "pull": ("object, joint or part", "draw a part open towards `target`"),
    "place_on": ("object, region", "set the held object down on the top of support `region`"),
    "push_to": ("object, region", "slide a floor object until it stands beside furniture `region`"),
    "take_out_of": ("object, region", "lift the object out of container `region` (opened first); it stays held"),
    "close_lid": ("object", "shut every lid or flap of a box or suitcase"),
    "open_lid": ("object", "open every lid or flap of a box or suitcase"),
}


SYSTEM_PROMPT = (
    "You plan for a household robot: a Franka Panda arm with a suction gripper on a mobile base. "
    "A hazard has been found in a room. Split the fix into a short ordered list of sub-tasks and state "
    "for each how to tell that it worked.\n\n"
    "Pick a method for every sub-task:\n"
    "- primitive: a motion-planned skill from the menu, the usual choice: reaching, grasping, carrying "
    "and placing a rigid object, pushing or pulling a part with a handle or a flat face.\n"
    "- sac: reinforcement learning (soft actor-critic) on a reward you write. Use it for contact-rich "
    "motions of a part with no good grasp point, where a planned path is not enough, such as turning "
    "a knob or switch to off.\n"
    "A sac sub-task needs reward terms; for a primitive they are optional shaping.\n\n"
    "Write object and joint names exactly as the scene lists them, or a bound role variable such as "
    "$hazard (preferred in predicates). Sub-task ids look like s1_pick. End with the final success "
    "predicates: what must hold once the whole fix is done."
)


def scene_text(spec: SceneSpec) -> str:
    """The scene as the planner sees it: instances, categories, where they rest, articulated parts.

    Object roles are left out: with a detected plan source they would give away the ground truth.
    """
    lines = [f"Room: {spec.room}. Objects:"]
    for o in spec.objects:
        where = f"inside {o.inside}" if o.inside else ("on the floor" if o.support == "floor" else f"on {o.support}")
        fixed = ", fixed furniture" if o.fixed else ""
        lines.append(f"- {o.name} ({o.asset.category}), {where}{fixed}")
        for j in o.joint_states:
            lo, hi = j.range
            lines.append(
                f"  joint {j.name}: {j.label} {j.type}, range {lo:.2f}..{hi:.2f}, closed {j.closed_value:.2f}, "
                f"now {j.value:.2f} ({j.open_fraction:.0%} open)"
            )
    return "\n".join(lines)


def bindings_text(bindings: dict[str, str], meanings: dict[str, str] | None = None) -> str:
    if not bindings:
        return "Role variables: none bound."
    parts = []
    for var, name in sorted(bindings.items()):
        meaning = (meanings or {}).get(var)
        parts.append(f"{var} = {name}" + (f" ({meaning})" if meaning else ""))
    return "Role variables: " + "; ".join(parts) + "."


def menu_text() -> str:
    """Primitive menu, reward kinds and predicates, compact: the prompt must fit a 4k-token local model."""
    from anomalygen.knowledge.predicates import PREDICATES

    prims = "\n".join(f"- {name}({args}): {doc}" for name, (args, doc) in PRIMITIVES.items())
    preds = "\n".join(f"- {p.name}({', '.join(p.args)}): {_first_sentence(p.meaning)}" for p in PREDICATES.values())
    terms = (
        "distance(a, b): a close to b; inside(a, b): a within b's box; lifted(a, target): a at least target m high; "
        "joint(joint, target): joint near target; upright(a): object a stays upright; action_penalty: discourages "
        "large motions. 'ee' is the gripper. Each term has a weight."
    )
    return (
        f"Primitive menu (params: object, region, joint, target, part, lift, release):\n{prims}\n\n"
        f"Reward term kinds: {terms}\n\n"
        "Success predicates: name and args; negate true inverts one. object, a, b: an object or role variable; "
        "container, support: also '*' (anything) or categories 'A|B'; label: a joint label or '*'; property: "
        f"e.g. sharp, toxic, medication; min, max, max_distance in metres; min_fraction, max_fraction 0..1.\n{preds}"
    )


def _first_sentence(text: str) -> str:
    cut = re.split(r"(?<=[.:])\s", text, maxsplit=1)[0]
    return cut.rstrip(":.") + "."


def hazard_text_from_task(task) -> str:
    """Ground-truth hazard brief: the task's own words."""
    parts = [f"Task: {task.name}. {task.description}"]
    if task.hazard_other:
        parts.append(f"Hazard: {task.hazard_other}.")
    if task.solution:
        parts.append(f"Intended fix: {task.solution}")
    if task.success_condition:
        parts.append(f"Safe end state: {task.success_condition}")
    return " ".join(parts)


def hazard_text_from_hypothesis(hyp: dict) -> str:
    """Detected hazard brief: only what the detector said (the task text would leak the ground truth)."""
    return f"Detected problem: {hyp.get('problem', '')} Suggested fix: {hyp.get('solution', '')}"


def class_text(hazard_class: str, kb) -> tuple[str, dict[str, str]]:
    hc = kb.hazard_classes.get(hazard_class) if kb is not None else None
    if hc is None:
        return f"Hazard class: {hazard_class} (not in the knowledge base).", {}
    return f"Hazard class {hc.id} ({hc.name}): {hc.why}", dict(hc.variables)


def user_prompt(spec: SceneSpec, hazard_class: str, hazard: str, bindings: dict[str, str], kb=None) -> str:
    klass, meanings = class_text(hazard_class, kb)
    return f"{scene_text(spec)}\n\n{klass} {hazard}\n{bindings_text(bindings, meanings)}\n\nWrite the plan."


@dataclass(frozen=True)
class Example:
    why: str
    spec: SceneSpec
    hazard: str
    answer: dict


@cache
def load_examples() -> tuple[Example, ...]:
    """The in-context examples (package data ``data/prompts/plan_examples.json``) with their scenes."""
    raw = json.loads(resources.files("anomalygen").joinpath("data/prompts/plan_examples.json").read_text("utf-8"))
    return tuple(
        Example(why=e["why"], spec=_example_spec(i, e), hazard=e["hazard"], answer=e["answer"])
        for i, e in enumerate(raw["examples"])
    )


def _example_spec(i: int, e: dict) -> SceneSpec:
    """A minimal SceneSpec for an example scene: only the fields the prompt and the validator read."""
    from anomalygen.schema import AssetRef

    objects = [
        PlacedObject(
            name=o["name"], asset=AssetRef(asset_id=f"example-{o['category']}", category=o["category"]),
            role=ObjectRole.SUPPORT if o.get("fixed") else ObjectRole.AUXILIARY, size=0.3, pos=[0.0, 0.0, 0.0],
            support=o.get("support", "floor"), inside=o.get("inside"), fixed=bool(o.get("fixed", False)),
            joint_states=[
                JointState(name=j["name"], label=j["label"], type=j["type"], value=j["value"],
                           range=tuple(j["range"]), closed_value=j["closed"])
                for j in o.get("joints", [])
            ],
        )
        for o in e["objects"]
    ]
    return SceneSpec(scene_id=f"example-{i}", task_id=f"example-{i}", room=e["room"], seed=0, objects=objects,
                     bindings=dict(e["bindings"]))


def messages(spec: SceneSpec, hazard_class: str, hazard: str, bindings: dict[str, str], kb=None) -> list[dict]:
    """System prompt with the menus, then the examples as earlier turns, then this scene."""
    convo = [{"role": "system", "content": f"{SYSTEM_PROMPT}\n\n{menu_text()}"}]
    for ex in load_examples():
        ex_user = f"{scene_text(ex.spec)}\n\n{ex.hazard}\n{bindings_text(ex.spec.bindings)}\n\nWrite the plan."
        convo.append({"role": "user", "content": ex_user})
        convo.append({"role": "assistant", "content": json.dumps(ex.answer, separators=(",", ":"))})
    convo.append({"role": "user", "content": user_prompt(spec, hazard_class, hazard, bindings, kb)})
    return convo
