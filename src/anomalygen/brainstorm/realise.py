"""Text realisation: name, explanation, description, solution and success condition from an Idea.

Why phrase banks and not sentence frames: diversity metrics (Self-BLEU, SBERT similarity) read the
*text*, and a few fixed frames make every text share most of its four-word runs with some other text
(Self-BLEU 0.80 on a 111-task run). Here every slot (opening, how the object, place, room and person
are said, the class's harm, the role's remark, the fix's lead and steps, the sentence layout) is an
independent draw from data/knowledge/phrasing.json, whose phrases hold further ``[a|b|c]`` choices.
All the words still come from the idea's own fields, so a text never claims what the scenario lacks.
Every choice comes from the caller's generator: the same seed gives the same words.
"""

from __future__ import annotations

import json
import re
from functools import lru_cache

import numpy as np

from anomalygen.brainstorm.idea import Idea, Texts
from anomalygen.knowledge import KnowledgeBase
from anomalygen.knowledge.base import KNOWLEDGE_DIR
from anomalygen.schema import DOOR, Placement

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

_ROOM_WORDS = {"living_room": "living room", "laundry_room": "laundry room"}

_VERBS = {
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
    "close_lid": ["Close", "Shut", "Lower the lid of"],
    "place_on": ["Put away", "Lift up", "Pick up"],
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


FIX_LEAD_P = 0.3
# How a description orders its opening, scene and harm: the sentences of each layout, and the single
# sentence a layout becomes when the role's sentence joins it (None: no change). ``{When}`` is drawn
# from _WHEN; capitalised keys are the capitalised words.
_LAYOUTS: tuple[tuple[tuple[str, ...], tuple[str, ...] | None], ...] = (
    (("{opening} {scene}, so {harm}.",), None),
    (("{Scene}.", "{Harm}."), ("{Scene}; {harm}.",)),
    (("{Harm}: {scene}.",), None),
    (("{opening} {scene} and {harm}.",), None),
    (("Because {scene}, {harm}.",), None),
    (("{Harm}, since {scene}.",), None),
    (("{Scene}, which means {harm}.",), None),
    (("{When} {scene}, {harm}.",), None),
)
_WHEN = ["if", "as long as", "while", "now that"]


def nice(name: str) -> str:
    if name in _NICE_NAMES:
        return _NICE_NAMES[name]
    words = re.sub(r"(?<=[a-z])(?=[A-Z])", " ", name).replace("_", " ")
    return words.lower() if not name.isupper() else words


def article(phrase: str) -> str:
    first = phrase.split()[0] if phrase else ""
    if (
        first.lower() in {"some", "the"}
        or phrase.endswith("s")
        and not phrase.endswith("ss")
        and first not in ("a", "an")
    ):
        return phrase if first.lower() in {"some", "the"} else f"some {phrase}"
    return ("an " if phrase[:1].lower() in "aeiou" else "a ") + phrase


def cap(text: str) -> str:
    return text[:1].upper() + text[1:] if text else text


def room_words(room: str) -> str:
    return _ROOM_WORDS.get(room, room.replace("_", " "))


_ALTERNATIVES = re.compile(r"\[([^\[\]]*)\]")


def _choice(rng: np.random.Generator, options: list[str]) -> str:
    """One option; any ``[a|b|c]`` inside it is a further independent choice (phrase-bank syntax)."""
    text = str(options[int(rng.integers(len(options)))])
    while "[" in text:
        text = _ALTERNATIVES.sub(lambda m: _pick(rng, m.group(1).split("|")), text, count=1)
    return text


def _pick(rng: np.random.Generator, options: list[str]) -> str:
    return options[int(rng.integers(len(options)))]


def _join(items: list[str], rng: np.random.Generator | None = None) -> str:
    if len(items) <= 1:
        return "".join(items)
    last = (
        " and "
        if rng is None
        else _pick(rng, [" and ", " plus ", " and also ", ", and ", " and even ", " together with "])
    )
    return ", ".join(items[:-1]) + last + items[-1]


def fix_phrase(idea: Idea, kb: KnowledgeBase, rng: np.random.Generator, part: str, say=nice) -> str:
    """The class's recipe in varied words, e.g. 'lift the pill and tuck it away in the medicine cabinet'."""
    hc = kb.hazard_classes[idea.class_id]
    names = {
        "object": say(idea.hazard),
        "container": (
            _pick(rng, ["", "", "nearby ", "closest ", "usual ", "proper ", "right "]) + say(idea.container)
        )
        if idea.container
        else "a safe place",
        "support": say(idea.support) if idea.support else "a raised surface",
    }
    pieces = []
    for step in hc.recipe:
        label = step.args.get("label", "")
        if "|" in label or not label:
            label = (
                part
                or (kb.articulation_part(hc, idea.container) if idea.container else None)
                or label.split("|")[0]
                or DOOR
            )
        if step.action == "open_joint" and step.args.get("object") == "$container":
            label = DOOR
        obj_var = step.args.get("object")
        obj = names["container"] if obj_var == "$container" else names["object"]
        container = obj if step.action == "open_joint" else names["container"]
        pieces.append(
            _choice(rng, bank()["steps"][step.action]).format(
                object=obj, container=container, support=names["support"], label=label
            )
        )
    out = pieces[0]
    for p in pieces[1:]:
        out += _choice(rng, bank()["step_join"]) + p
    return out


@lru_cache(maxsize=1)
def bank() -> dict:
    """The phrase banks (data/knowledge/phrasing.json), loaded once."""
    return json.loads((KNOWLEDGE_DIR / "phrasing.json").read_text(encoding="utf-8"))


def _adjective(kb: KnowledgeBase, obj: str, rng: np.random.Generator) -> str:
    """A word for what makes the object dangerous (its first knowledge-base property with words)."""
    info = kb.objects.get(obj)
    options = [bank()["adjective"][p] for p in (info.properties if info else []) if p in bank()["adjective"]]
    return _choice(rng, options[0]) if options else ""


def _object_np(obj: str, adj: str, rng: np.random.Generator) -> str:
    """How the hazard object is referred to: 'the bare knife', 'a knife', 'someone's knife'."""
    core = f"{adj} {obj}" if adj else obj
    form = int(rng.integers(4))
    if form == 0:
        return f"the {core}"
    if form == 1:
        return article(core)
    if form == 2:
        return f"that {core}"
    det = _pick(rng, ["the", "a", "one", "this"])
    det = "an" if det == "a" and not obj.endswith("s") else det
    return (
        f"{det} {_pick(rng, ['abandoned', 'unattended', 'overlooked'])} {obj}"
        if det == "an"
        else f"{det} {_pick(rng, ['forgotten', 'stray', 'lone', 'misplaced'])} {obj}"
    )


def _tidy(text: str) -> str:
    """Collapse spaces and a doubled word ('the window window' when the part is the object)."""
    text = re.sub(r"\s+", " ", text).strip()
    return re.sub(r"\b(\w+) \1\b", r"\1", text, flags=re.IGNORECASE)


def _words(text: str) -> int:
    return len(text.split())


def _name(slots: dict[str, str], frames: list[str], rng: np.random.Generator) -> str:
    """A 3-8 word title; frames that come out too long or short are redrawn, then a plain fallback."""
    for _ in range(4):
        name = cap(_choice(rng, frames).format(**slots)).rstrip(".")
        if 3 <= _words(name) <= 8:
            return name
    return cap(f"{slots['Verb']} the {slots['obj']}")


def realise(idea: Idea, kb: KnowledgeBase, rng: np.random.Generator, *, perspective: bool = True,
            called: dict[str, str] | None = None) -> Texts:
    """Words for an idea. ``perspective`` adds the agent's point of view (role-play modes).

    Every slot (opening, how the object/place/person are said, the harm, the role's concern, the fix
    lead and steps, the sentence layout) is an independent draw, so two texts about similar
    scenarios rarely share a four-word run; all words still come from the idea's own fields.
    """
    b = bank()
    hc = kb.hazard_classes[idea.class_id]

    def say(name: str) -> str:  # an object the user called otherwise is said in the user's words
        return (called or {}).get(name) or nice(name)

    room = _choice(rng, b["room_synonyms"].get(idea.room, [room_words(idea.room)]))
    hazard = say(idea.hazard)
    container = say(idea.container) if idea.container else "a safe place"
    support = say(idea.support) if idea.support else "a raised surface"
    articulated = hc.articulation is not None and hc.about_target
    part = (kb.articulation_part(hc, idea.hazard) or DOOR) if articulated else ""
    state = hc.articulation.initial_state if hc.articulation else ""
    person = idea.person or hc.at_risk
    if person == hc.at_risk:  # the class-level phrase reads as a list; its first part is the people
        person = person.split(",")[0].split(":")[0]
    person_short = person.split(" who ")[0]
    first, _, rest = person.partition(" ")
    if (
        first in ("a", "the") and rest and rng.random() < 0.5
    ):  # 'our toddler', 'any guest': same person, other words
        person = _pick(rng, ["any", "our"]) + " " + rest if first == "a" else person
    adj = "" if articulated else _adjective(kb, idea.hazard, rng)
    verbs = _VERBS.get(hc.id) or _ACTION_VERBS.get(hc.recipe[-1].action) or ["Fix"]
    verb = _choice(rng, verbs)
    risk = _choice(rng, class_bank(b, "risk_word", hc))
    pshort = "" if articulated else place_phrase_bank(idea.placement, room, rng, fragment=_place_fragment(hc), say=say)
    beside = idea.placement.other  # already said by the place
    co_names = [say(c) for c in idea.co_objects if c not in (idea.hazard, idea.container, beside)]
    if "co_objects" not in idea.borrowed and len(co_names) > 1:
        # background clutter is detail: name one piece, unless borrowing the setting is the idea's point
        co_names = [co_names[int(rng.integers(len(co_names)))]]
    co_words = [article(c) for c in co_names]
    co_words = [
        w
        if not w.startswith(("a ", "an ")) or rng.random() < 0.5
        else f"{_pick(rng, ['the', 'one', 'that'])} {c}"
        for w, c in zip(co_words, co_names, strict=True)
    ]
    co = _choice(rng, b["co"]).format(x=_join(co_words, rng)) if co_names else ""
    state_words = b["state"].get(state, ["as it is"])

    # ---- name
    slots = {
        "Verb": verb,
        "obj": hazard,
        "Obj": cap(hazard),
        "room": room,
        "Room": cap(room),
        "risk": risk,
        "Risk": cap(risk),
        "pshort": pshort,
        "person_short": person_short,
        "part": part,
        "adj_obj": f"{adj} {hazard}" if adj else hazard,
        "Adj_obj": cap(f"{adj} {hazard}" if adj else hazard),
        "state_word": {"on": "running", "open": "open", "closed": "shut"}.get(state, state),
    }
    name = _name(slots, b["artic_name_frames"] if articulated else b["name_frames"], rng)

    # ---- description pieces
    if articulated:
        owner = _choice(rng, [f"the {room} {hazard}", f"the {hazard}", f"the {hazard} in the {room}"])
        scene = (
            owner
            if part in hazard
            else (
                f"the {part} of {owner}"
                if " in " in owner
                else _choice(rng, [f"the {part} of {owner}", f"{owner}'s {part}"])
            )
        )
        scene += " " + _choice(rng, state_words) + co
        if room not in scene:
            scene += f" in the {room}"
    else:
        place = pshort  # the same words as the name, so title and description never disagree
        np_ = _object_np(hazard, adj, rng)
        if (
            not adj and room not in place and rng.random() < 0.3
        ):  # 'the kitchen knife': the room as a modifier
            np_ = re.sub(r"^a ([aeiou])", r"an \1", np_.replace(hazard, f"{room} {hazard}", 1))
        scene = f"{np_} {_choice(rng, b['lie'])} {place}{co}"
        if room not in scene:
            scene += _choice(rng, b["room_mention"]).format(room=room)
    harm = _choice(rng, class_bank(b, "harm", hc))
    if not re.match(r"(a|an|the|our|any|whoever|someone|everyone) ", person):  # plural people: no "'s"
        harm = re.sub(r"\{person\}'s (\w+)", r"the \1 of {person}", harm)
    harm = harm.format(person=person, obj=hazard)
    lead = _choice(rng, b["fix_lead"]) + " " if rng.random() < FIX_LEAD_P else ""
    fix = f"{lead}{fix_phrase(idea, kb, rng, part, say)}."
    opening = _choice(rng, b["opening"])
    role_sentence = ""
    if perspective and idea.agent and idea.agent in kb.roles and rng.random() < 0.75:
        role = kb.roles[idea.agent]
        lead = _choice(rng, b["role_lead"]).format(role=role.name.lower(), Role=role.name)
        views = b["role_view"].get(role.id, [role.perspective])
        if articulated:  # a fridge or window is shut, not put away
            views = [v for v in views if not any(w in v for w in ("put away", "belongs", "should go"))]
        view = _choice(rng, views).format(obj=hazard)
        role_sentence = f"{lead} {view}"

    plain, with_role = _LAYOUTS[int(rng.integers(len(_LAYOUTS)))]
    templates = with_role if role_sentence and with_role else plain
    when = cap(_pick(rng, _WHEN)) if any("{When}" in tpl for tpl in templates) else ""
    words = {"opening": opening, "scene": scene, "Scene": cap(scene), "harm": harm, "Harm": cap(harm), "When": when}
    body = [tpl.format(**words) for tpl in templates]
    if role_sentence:
        if rng.random() < 0.5:
            body = [f"{cap(role_sentence)}."] + body
        else:
            body = body + [f"{cap(role_sentence)}."]
    body.append(cap(fix))
    description = " ".join(cap(x.strip()) for x in body if x.strip())
    description = _tidy(description)
    name = _tidy(name)

    solution = hc.solution.format(hazard=hazard, container=container, support=support) if hc.solution else ""
    success = (
        hc.success_text.format(hazard=hazard, container=container, support=support) if hc.success_text else ""
    )
    ex_slots = {
        "why": hc.why,
        "why_lower": hc.why[:1].lower() + hc.why[1:],
        "mechanism": hc.mechanism,
        "person": person,
        "Person": cap(person),
        "at_risk": hc.at_risk,
        "hazard_the": f"the {hazard}",
        "Hazard_a": cap(article(hazard)),
        "place": pshort or f"in the {room}",
    }
    explanation = _choice(rng, _EXPLANATION_FRAMES).format(**ex_slots)
    return Texts(
        name=name,
        explanation=explanation,
        description=description,
        solution=solution,
        success_condition=success,
    )


def class_bank(b: dict, slot: str, hc) -> list[str]:
    """A class's own phrases for a slot (harm, risk word), else its mechanism's (composed classes)."""
    own = b[slot].get(hc.id)
    if own:
        return own
    mechanism = hc.composition.mechanism if hc.composition is not None else ""
    return b[f"{slot}_by_mechanism"].get(mechanism) or ["[a|the] hazard"]


def _place_fragment(hc) -> str | None:
    return hc.composition.place if hc.composition is not None and not hc.composition.legacy else None


def place_phrase_bank(placement: Placement, room: str, rng: np.random.Generator, *, fragment: str | None = None,
                      say=nice) -> str:
    """Where the object is, from the phrase bank (containers/supports name the catalogue object); a
    composed class's place may have words of its own (a heavy pan 'on the top shelf', not any shelf)."""
    own = bank().get("place_by_fragment", {}).get(fragment or "")
    if own:
        return _choice(rng, own).format(room=room)
    holder = _HOLDER_PLACES.get(placement.relation) if placement.other is not None else None
    if holder:
        return _choice(rng, holder).format(x=say(placement.other))
    options = bank()["place"].get(placement.key, ["in the {room}"])  # phrasing.json's "place", by compact word
    if room != "kitchen":  # sinks, hobs and kettles only stand in kitchens
        options = [o for o in options if not any(w in o for w in _KITCHEN_ONLY)] or options
    return _choice(rng, options).format(room=room)


# placements in, on or near another object (inside the Refrigerator), by relation: the object is {x}
_HOLDER_PLACES = {
    "inside": ["inside the {x}", "at the back of the {x}", "tucked into the {x}", "deep in the {x}", "in the {x}"],
    "on": ["on top of the {x}", "on the {x}", "atop the {x}", "perched on the {x}"],
    "near": ["right next to the {x}", "beside the {x}", "up against the {x}", "a hand's width from the {x}", "by the {x}"],
}
_KITCHEN_ONLY = ("sink", "hob", "chopping", "kettle", "toaster", "bread bin")
