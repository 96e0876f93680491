"""Text realisation: name, explanation, description, solution and success condition from an Idea.

Why plain sentences and not phrase banks: the banks drew every slot independently to buy Self-BLEU,
and a blind reader found persona remarks that had nothing to do with the hazard, spill words for
pills and kitchen words in bathrooms (issue 39). The description is now built by
``brainstorm/describe.py`` from fragments each tagged with what it fits (a place phrase for one
placement key, the class's own danger and fix), and a test checks every tag against its task. All
the words come from the idea's own fields; every choice comes from the caller's generator.
"""

from __future__ import annotations

import re

import numpy as np

from anomalygen.brainstorm.describe import _a as indefinite
from anomalygen.brainstorm.describe import cap, describe_fragments, fix_words, pick, reason, words
from anomalygen.brainstorm.idea import Idea, Texts
from anomalygen.knowledge import KnowledgeBase
from anomalygen.knowledge.grounding import name_words
from anomalygen.knowledge.households import load_households
from anomalygen.schema import DOOR

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
    "Safe": "lockable box",  # a small lockable store (households.json): 'the safe' reads oddly for a coin or a toy
}

_ROOM_WORDS = {"living_room": "living room", "laundry_room": "laundry room"}

_VERBS = {
    "turn_off_running_tap": ["Turn off", "Shut off"],
    "dispose_spoiled_food": ["Throw out", "Bin", "Dispose of", "Get rid of", "Discard"],
    "store_perishable_food": ["Refrigerate", "Chill", "Put away", "Cool down"],
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
    "push_to": ["Push aside", "Slide away", "Move"],
    "take_off": ["Take down", "Clear", "Lift off", "Move"],
    "move_away": ["Move away", "Shift", "Clear"],
    "close_lid": ["Close", "Shut"],
    "open_lid": ["Open"],
    "place_on": ["Put away", "Lift up", "Pick up"],
    "place_inside": ["Put away", "Store", "Tidy away"],
    "pick": ["Pick up", "Collect"],
    "take_out_of": ["Take out", "Lift out"],
    "rotate_inward": ["Turn in", "Turn"],
    "stand_upright": ["Stand up", "Set upright"],
}

_EXPLANATION_FRAMES = [
    "{why}",
    "{Hazard_a} {place} is {mechanism}. {why}",
    "{why} Here it is {person} who is most exposed.",
    "The problem is {mechanism}: {why_lower}",
    "{Person} could be harmed, because {why_lower}",
    "{why} Leaving {hazard_the} {place} makes that likely.",
    "It is {mechanism}, and {at_risk} are at risk. {why}",
]


def nice(name: str) -> str:
    if name in _NICE_NAMES:
        return _NICE_NAMES[name]
    words = name_words(name)
    return words.lower() if not name.isupper() else words


def article(phrase: str) -> str:
    """The phrase with its article (describe's rule: a USB stick, some mouldy bread), kept if it has one."""
    first = phrase.split()[0] if phrase else ""
    return phrase if first.lower() in {"some", "the", "a", "an"} else indefinite(phrase)


def room_words(room: str) -> str:
    return _ROOM_WORDS.get(room, room.replace("_", " "))


def _tidy(text: str) -> str:
    """Collapse spaces and a doubled word ('the window window' when the part is the object)."""
    text = re.sub(r"\s+", " ", text).strip()
    return re.sub(r"\b(\w+) \1\b", r"\1", text, flags=re.IGNORECASE)


def _words(text: str) -> int:
    return len(text.split())


def _name(slots: dict[str, str], frames: list[str], rng: np.random.Generator) -> str:
    """A 3-8 word title; frames that come out too long or short are redrawn, then a plain fallback."""
    for _ in range(4):
        name = cap(pick(rng, frames).format(**slots)).rstrip(".")
        if 3 <= _words(name) <= 8:
            return name
    return cap(f"{slots['Verb']} the {slots['obj']}")


def _sayer(called: dict[str, str] | None):
    def say(name: str) -> str:  # an object the user called otherwise is said in the user's words
        return (called or {}).get(name) or nice(name)

    return say


def person_at_risk(idea: Idea, hc) -> str:
    """The person the text names: the idea's, or the first people of the class's at-risk phrase."""
    person = idea.person or hc.at_risk
    if person == hc.at_risk:  # the class-level phrase reads as a list; its first part is the people
        person = person.split(",")[0].split(":")[0]
    return person


def _task_words(idea: Idea, kb: KnowledgeBase, called: dict[str, str] | None) -> dict:
    """How this idea's objects, part, state and person are said: one computation for the name, the
    description and the fix alike."""
    hc = kb.hazard_classes[idea.class_id]
    say = _sayer(called)
    articulated = hc.articulation is not None and hc.about_target
    part = (kb.articulation_part(hc, idea.hazard) or DOOR) if articulated else ""
    if not part and hc.articulation is not None and hc.articulation.variable == hc.hazard_variable \
            and idea.hazard in load_households().fixtures:  # the tap of a sink left running
        part = hc.articulation.part.split("|")[0]
    return {
        "say": say, "person": person_at_risk(idea, hc), "part": part,
        "state": hc.articulation.initial_state if hc.articulation else "", "room": room_words(idea.room),
        "container": say(idea.container) if idea.container else "a safe place",
        "support": say(idea.support) if idea.support else "a raised surface",
    }


def fragments(idea: Idea, kb: KnowledgeBase, rng: np.random.Generator, *, called: dict[str, str] | None = None):
    """The description's tagged fragments (``describe.describe_fragments``) with this idea's words."""
    return describe_fragments(idea, kb, rng, **_task_words(idea, kb, called))


def realise(idea: Idea, kb: KnowledgeBase, rng: np.random.Generator, *, called: dict[str, str] | None = None) -> Texts:
    """Words for an idea: a name, and a description of the situation, the danger with who is at risk,
    and the fix (``describe_fragments``). A role chooses what is proposed and provenance records it;
    its remarks are not in the text (issue 39)."""
    hc = kb.hazard_classes[idea.class_id]
    w = _task_words(idea, kb, called)
    frags = describe_fragments(idea, kb, rng, **w)  # first: the same generator state gives the same words
    hazard, container, support, part, state, person, room = (
        w["say"](idea.hazard), w["container"], w["support"], w["part"], w["state"], w["person"], w["room"])
    articulated = hc.articulation is not None and hc.about_target
    verbs = _VERBS.get(hc.id) or _ACTION_VERBS.get(hc.recipe[-1].action) or ["Fix"]
    verb = pick(rng, verbs)

    # ---- name and description: plain sentences, every fragment drawn for this task (describe.py)
    place = next((f.text for f in frags if f.kind in ("place", "relation", "place_fragment")), f"in the {room}")
    slots = {
        "Verb": verb,
        "obj": hazard,
        "Obj": cap(hazard),
        "room": room,
        "place": place,
        "part": "" if state == "on" and part in words()["control_parts"] else part,  # the kettle is on, not its knob
        "state_word": {"on": "on", "open": "open", "closed": "shut"}.get(state, state),
    }
    said_by_state = articulated or not any(f.kind in ("place", "relation", "place_fragment") for f in frags)
    frames = words()["artic_name_frames" if said_by_state else "name_frames"]
    name = _name(slots, frames, rng)
    description = _tidy(" ".join(f.text for f in frags if f.kind == "sentence"))
    name = _tidy(name)

    solution = fix_words(hc, hazard=hazard, container=container, support=support, part=part)
    success = (
        hc.success_text.format(hazard=hazard, container=container, support=support) if hc.success_text else ""
    )
    why = reason(kb, hc, idea.hazard)  # the description's own reason
    ex_slots = {
        "why": why,
        "why_lower": why[:1].lower() + why[1:],
        "mechanism": hc.mechanism,
        "person": person,
        "Person": cap(person),
        "at_risk": hc.at_risk,
        "hazard_the": f"the {hazard}",
        "Hazard_a": cap(article(hazard)),
        "place": place if not articulated else f"in the {room}",
    }
    # a fixture said by its state has no place to leave it in ("leaving the sink in the kitchen")
    frames = [f for f in _EXPLANATION_FRAMES if "{place}" not in f] if said_by_state else _EXPLANATION_FRAMES
    explanation = pick(rng, frames).format(**ex_slots)
    return Texts(
        name=name,
        explanation=explanation,
        description=description,
        solution=solution,
        success_condition=success,
    )
