"""Text realisation: name, explanation, description, solution and success condition from an Idea.

Why not one template: diversity metrics (Self-BLEU, SBERT similarity) read the *text*, and a single
sentence frame would make every task look alike however different the scenarios were. Each field is
built from several interchangeable sentence frames, filled with slot phrases that themselves vary
(how a place, a person, an object or a fix is said), and agents add their own perspective. All
choices come from the caller's generator, so the same seed gives the same words.
"""

from __future__ import annotations

import re

import numpy as np

from anomalygen.brainstorm.idea import Idea, Texts
from anomalygen.knowledge import KnowledgeBase

_NICE_NAMES = {
    "StorageFurniture": "cabinet",
    "CoffeeMachine": "coffee machine",
    "KitchenPot": "cooking pot",
    "TrashCan": "bin",
    "WashingMachine": "washing machine",
    "USB": "USB stick",
    "FoldingChair": "folding chair",
    "Remote": "remote control",
    "Dispenser": "soap dispenser",
    "Display": "monitor",
    "aa_battery": "AA battery",
    "hot_mug": "mug of hot tea",
    "moldy_bread": "mouldy bread",
    "paper_ball": "crumpled paper ball",
    "lego_brick": "toy brick",
    "raw_meat_tray": "tray of raw meat",
    "leftover_container": "box of leftovers",
    "spoiled_milk_carton": "carton of sour milk",
    "medicine_cabinet": "medicine cabinet",
}

_PLACE = {
    "floor": ["on the {room} floor", "lying on the floor of the {room}", "down on the {room} floor", "on the floor by the wall"],
    "walkway": [
        "in the middle of the {room} walkway",
        "right where people walk through the {room}",
        "across the path through the {room}",
        "in the open stretch of the {room} floor",
    ],
    "table": ["on the {room} table", "on top of the table in the {room}", "on the table", "among the things on the table"],
    "low_table": ["on the low coffee table", "on a low table in the {room}", "on the little table at toddler height", "on the low side table"],
    "table_edge": ["at the very edge of the table", "hanging over the table's edge", "close to the rim of the {room} table", "on the table corner"],
    "counter": ["on the {room} counter", "on the worktop", "out on the counter", "on the kitchen counter next to the sink"],
    "counter_edge": ["right at the edge of the counter", "on the lip of the worktop", "balanced at the front edge of the counter", "at the counter's edge"],
    "shelf": ["on a shelf", "up on the {room} shelf", "on the open shelf", "on a shelf among other things"],
}

_ROOM_WORDS = {"living_room": "living room", "laundry_room": "laundry room"}

_OCCASIONS = [
    "dinner", "a birthday party", "the weekly shop", "a busy morning", "movie night", "homework time",
    "a long day at work", "unpacking the groceries", "a visit from the grandparents", "a rushed breakfast",
    "a weekend of DIY", "the school run", "a late-night snack", "spring cleaning",
]

_VERBS = {
    "dispose_spoiled_food": ["Throw out", "Bin", "Dispose of", "Get rid of", "Discard"],
    "store_perishable_food": ["Refrigerate", "Chill", "Put back in the fridge", "Cool down"],
    "pick_up_floor_litter": ["Pick up", "Clear", "Bin", "Collect"],
    "reduce_tripping_hazards": ["Clear", "Tidy away", "Pick up", "Move"],
    "clear_cable_from_walkway": ["Clear", "Lift", "Reroute", "Move"],
    "secure_medications": ["Secure", "Lock away", "Put away", "Store"],
    "keep_sharp_away_from_children": ["Secure", "Put away", "Take away", "Store"],
    "store_sharp_objects": ["Store", "Put away", "Tidy away", "Stow"],
    "remove_choking_hazards": ["Remove", "Pick up", "Put away", "Collect"],
    "manage_chemical_risks": ["Store", "Put away", "Secure", "Shut away"],
    "keep_chemicals_from_children": ["Secure", "Lock away", "Move", "Put away"],
    "keep_fire_starters_from_children": ["Secure", "Lock away", "Take away", "Hide"],
}
_ACTION_VERBS = {
    "close_joint": ["Close", "Shut", "Push shut"],
    "open_joint": ["Open", "Crack open", "Prop open"],
    "switch_off": ["Switch off", "Turn off", "Power down"],
    "move_away_from_edge": ["Move back", "Push back", "Re-centre", "Secure"],
}

_NAME_FRAMES = [
    "{Verb} the {hazard} {place}",
    "{Verb} the {hazard} in the {room}",
    "{Hazard} {place}",
    "{Mechanism_cap}",
    "{Verb} the {hazard} before {person_short} gets to it",
    "{Class}: the {hazard} in the {room}",
    "The {hazard} {place}",
    "{Verb} the {room} {hazard}",
]
_ARTIC_NAME_FRAMES = [
    "{Verb} the {hazard} {part}",
    "{Verb} the {part} of the {room} {hazard}",
    "{Hazard} {part} left {state}",
    "{Class} in the {room}",
    "{Mechanism_cap}",
    "The {room} {hazard} with its {part} {state}",
]

_EXPLANATION_FRAMES = [
    "{why}",
    "{Hazard_a} {place} is {mechanism}. {why}",
    "{why} Here it is {person} who is most exposed.",
    "The problem is {mechanism}: {why_lower}",
    "{Person} could be harmed, because {why_lower}",
    "{why} Leaving {hazard_the} {place} makes that likely.",
    "It is {mechanism}, and {at_risk} are at risk. {why}",
]

_CONTEXT_FRAMES = [
    "{Hazard_a} has been left {place}{co}.",
    "After {occasion}, {hazard_a} ended up {place}{co}.",
    "Someone put {hazard_a} down {place}{co} and forgot about it.",
    "{Hazard_a} sits {place}{co}.",
    "In the {room}, {hazard_a} is {place}{co}.",
    "There is {hazard_a} {place}{co}, left behind after {occasion}.",
]
_ARTIC_CONTEXT_FRAMES = [
    "The {part} of the {hazard} in the {room} has been left {state}{co}.",
    "After {occasion}, nobody {undo} the {part} of the {hazard}{co}.",
    "In the {room}, the {hazard} stands with its {part} {state}{co}.",
    "The {room} {hazard} was left with its {part} {state}{co}.",
]
_RISK_FRAMES = [
    "{Person} is around and could get hurt.",
    "This puts {person} at risk.",
    "{Person} often comes through here.",
    "It would only take a moment for {person} to get into trouble.",
    "{Person} is the one most likely to suffer from it.",
    "",
]
_FIX_FRAMES = [
    "The robot should {solution}",
    "To resolve it, the robot will {solution}",
    "A suction-gripper arm can fix this: {solution}",
    "Fix: {solution}",
    "The robot's job is to {solution}",
]
_PERSPECTIVE_FRAMES = [
    "As the {role}, someone who {perspective}, I would flag this.",
    "This caught the eye of the {role}, who {perspective}.",
    "The {role}, who {perspective}, raised it.",
    "Flagged by the {role}, who {perspective}.",
]

#: Ways to say each recipe step (the description's fix sentence is built from the class's recipe).
_STEP_WORDS = {
    "pick": ["pick up the {object}", "lift the {object}", "grab the {object} with its suction cup", "take hold of the {object}"],
    "place_inside": ["put it in the {container}", "drop it into the {container}", "store it inside the {container}", "tuck it away in the {container}"],
    "place_on": ["lay it on the {support}", "set it down on the {support}", "rest it on top of the {support}"],
    "open_joint": ["open the {container} {label}", "pull the {container} {label} open", "swing the {object} {label} open"],
    "close_joint": ["close the {label}", "push the {label} shut", "swing the {label} closed", "shut the {label} again"],
    "switch_off": ["turn the {label} to off", "switch it off at the {label}", "twist the {label} back to zero"],
    "move_away_from_edge": ["slide the {object} back from the edge", "move the {object} towards the middle", "push the {object} to a safer spot further in"],
}
_STEP_JOIN = [" and then ", ", then ", " and ", "; after that, "]

_UNDO = {"open": "closed", "closed": "opened", "on": "switched off", "off": "switched on"}


def nice(name: str) -> str:
    if name in _NICE_NAMES:
        return _NICE_NAMES[name]
    words = re.sub(r"(?<=[a-z])(?=[A-Z])", " ", name).replace("_", " ")
    return words.lower() if not name.isupper() else words


def article(phrase: str) -> str:
    first = phrase.split()[0] if phrase else ""
    if first.lower() in {"some", "the"} or phrase.endswith("s") and not phrase.endswith("ss") and first not in ("a", "an"):
        return phrase if first.lower() in {"some", "the"} else f"some {phrase}"
    return ("an " if phrase[:1].lower() in "aeiou" else "a ") + phrase


def cap(text: str) -> str:
    return text[:1].upper() + text[1:] if text else text


def room_words(room: str) -> str:
    return _ROOM_WORDS.get(room, room.replace("_", " "))


def place_phrase(placement: str, room: str, rng: np.random.Generator) -> str:
    if placement.startswith("inside:"):
        options = ["inside the {x}", "at the back of the {x}", "tucked into the {x}"]
        return str(rng.choice(options)).format(x=nice(placement.split(":", 1)[1]))
    if placement.startswith("on:"):
        return str(rng.choice(["on top of the {x}", "on the {x}"])).format(x=nice(placement.split(":", 1)[1]))
    return str(rng.choice(_PLACE.get(placement, ["in the {room}"]))).format(room=room_words(room))


def _choice(rng: np.random.Generator, options: list[str]) -> str:
    return str(options[int(rng.integers(len(options)))])


def _join(items: list[str]) -> str:
    if len(items) <= 1:
        return "".join(items)
    return ", ".join(items[:-1]) + " and " + items[-1]


def fix_phrase(idea: Idea, kb: KnowledgeBase, rng: np.random.Generator, part: str) -> str:
    """The class's recipe in varied words, e.g. 'lift the pill and tuck it away in the medicine cabinet'."""
    hc = kb.hazard_classes[idea.class_id]
    names = {
        "object": nice(idea.hazard),
        "container": nice(idea.container) if idea.container else "a safe place",
        "support": nice(idea.support) if idea.support else "a raised surface",
    }
    pieces = []
    for step in hc.recipe:
        label = step.args.get("label", "")
        if "|" in label or not label:
            label = part or (kb.articulation_part(hc, idea.container) if idea.container else None) or label.split("|")[0] or "door"
        if step.action == "open_joint" and step.args.get("object") == "$container":
            label = "door"
        obj_var = step.args.get("object")
        obj = names["container"] if obj_var == "$container" else names["object"]
        pieces.append(_choice(rng, _STEP_WORDS[step.action]).format(object=obj, container=names["container"], support=names["support"], label=label))
    out = pieces[0]
    for p in pieces[1:]:
        out += _choice(rng, _STEP_JOIN) + p
    return out


def realise(idea: Idea, kb: KnowledgeBase, rng: np.random.Generator, *, perspective: bool = True) -> Texts:
    """Words for an idea. ``perspective`` adds the agent's point of view (role-play modes)."""
    hc = kb.hazard_classes[idea.class_id]
    room = room_words(idea.room)
    hazard = nice(idea.hazard)
    container = nice(idea.container) if idea.container else "a safe place"
    support = nice(idea.support) if idea.support else "a raised surface"
    articulated = hc.articulation is not None and hc.hazard_variable == "$target"
    part = kb.articulation_part(hc, idea.hazard) or "door" if articulated else ""
    state = hc.articulation.initial_state if hc.articulation else ""
    place = place_phrase(idea.placement, idea.room, rng)
    person = idea.person or hc.at_risk
    co_names = [nice(c) for c in idea.co_objects if c not in (idea.hazard, idea.container)]
    co = ""
    if co_names:
        co = _choice(rng, [" next to {x}", ", beside {x}", " among {x}", ", close to {x}"]).format(
            x=_join([article(c) for c in co_names])
        )
    slots = {
        "hazard": hazard,
        "Hazard": cap(hazard),
        "hazard_a": article(hazard),
        "Hazard_a": cap(article(hazard)),
        "hazard_the": f"the {hazard}",
        "place": place,
        "room": room,
        "person": person,
        "Person": cap(person),
        "person_short": person.split(" who ")[0],
        "mechanism": hc.mechanism,
        "Mechanism_cap": cap(hc.mechanism),
        "why": hc.why,
        "why_lower": hc.why[:1].lower() + hc.why[1:],
        "at_risk": hc.at_risk,
        "Class": hc.name,
        "part": part,
        "state": {"on": "running", "off": "off"}.get(state, state),
        "undo": _UNDO.get(state, "fixed"),
        "occasion": _choice(rng, _OCCASIONS),
        "co": co,
    }
    verbs = _VERBS.get(hc.id) or _ACTION_VERBS.get(hc.recipe[-1].action) or ["Fix"]
    slots["Verb"] = _choice(rng, verbs)
    frames = _ARTIC_NAME_FRAMES if articulated else _NAME_FRAMES
    name = cap(_choice(rng, frames).format(**slots)).rstrip(".")

    solution = hc.solution.format(hazard=hazard, container=container, support=support) if hc.solution else ""
    success = hc.success_text.format(hazard=hazard, container=container, support=support) if hc.success_text else ""
    explanation = _choice(rng, _EXPLANATION_FRAMES).format(**slots)

    sentences = [_choice(rng, _ARTIC_CONTEXT_FRAMES if articulated else _CONTEXT_FRAMES).format(**slots)]
    risk = _choice(rng, _RISK_FRAMES).format(**slots)
    if risk:
        sentences.append(risk)
    if perspective and idea.agent and rng.random() < 0.4:
        role = kb.roles[idea.agent] if idea.agent in kb.roles else None
        if role is not None:
            persp = role.perspective
            sentences.insert(
                int(rng.integers(0, 2)) * len(sentences),
                _choice(rng, _PERSPECTIVE_FRAMES).format(role=role.name.lower(), perspective=persp),
            )
    sentences.append(_choice(rng, _FIX_FRAMES).format(solution=fix_phrase(idea, kb, rng, part) + "."))
    description = " ".join(s.strip() for s in sentences if s.strip())
    return Texts(name=name, explanation=explanation, description=description, solution=solution, success_condition=success)
