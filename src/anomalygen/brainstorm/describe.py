"""A task's name and description in plain sentences, each fragment tagged with what it fits.

Why: the phrase banks of ``realise`` drew every slot independently to buy Self-BLEU, and a blind
reader found the price: persona remarks that had nothing to do with the hazard, spill words for pills,
"scorch what lies under it" for a pan handle, a counter "next to the hob" in a bathroom, a fridge
"in the doorway gap" (issue 39). Here a description is plain sentences: the situation, the danger,
who is at risk, and the fix, and every fragment is drawn from a list kept for exactly one
thing: a place phrase for one placement key, a state phrase for one joint state, the danger and the
fix from the hazard class's own knowledge-base text. ``fragments`` returns each fragment with its
tag, and a test checks that every tag agrees with the task it was drawn for. A role chooses *what*
is proposed (provenance records it); its remarks are not in the text.

The data is ``data/knowledge/describing.json``. Every choice comes from the caller's generator.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from anomalygen.brainstorm.idea import secondary_variables
from anomalygen.knowledge.base import KNOWLEDGE_DIR
from anomalygen.knowledge.households import load_households
from anomalygen.schema import DOOR


@dataclass(frozen=True)
class Fragment:
    """One piece of a generated text and what it was written for: ``kind`` is the slot (place, relation,
    place_fragment, state, quality, room, danger, person, fix, or a whole sentence), ``fits`` the value
    of the task it must agree with."""

    text: str
    kind: str
    fits: str


@lru_cache(maxsize=1)
def words() -> dict:
    """The tagged phrase lists (data/knowledge/describing.json), loaded once."""
    return json.loads((KNOWLEDGE_DIR / "describing.json").read_text(encoding="utf-8"))


def person_fits(person: str, *, room: str, names) -> bool:
    """Whether a person at risk makes sense in this scene ('people_fit' in describing.json): the cook
    belongs in a kitchen, a child in the bath needs a bathtub, the family asleep upstairs is not in the
    bedroom. Every condition a row lists must hold: ``rooms`` (the room is one of them), ``not_rooms``,
    ``objects`` (one of the scene's names contains one of them)."""
    need = words()["people_fit"].get(person)
    if need is None:
        return True
    if "rooms" in need and room not in need["rooms"]:
        return False
    if room in need.get("not_rooms", ()):
        return False
    said = " ".join(str(n).lower() for n in names if n)
    return "objects" not in need or any(o in said for o in need["objects"])


def people_for(hc, idea_like: dict) -> list[str]:
    """The class's people at risk who fit this scene (``person_fits``)."""
    return [p for p in hc.people if person_fits(p, **idea_like)]


def pick(rng: np.random.Generator, options: list[str]) -> str:
    return str(options[int(rng.integers(len(options)))])


def place_fragment(key: str, fragment: str | None, other: str | None, relation: str, rng: np.random.Generator,
                   say) -> Fragment:
    """Where the object is: words for its composed place (the top shelf), its placement key (the edge of
    the counter) or its relation to another object (beside the crib). Never a detail the scene lacks."""
    w = words()
    if fragment and fragment in w["place_by_fragment"]:
        return Fragment(pick(rng, w["place_by_fragment"][fragment]), "place_fragment", fragment)
    if other is not None:
        return Fragment(pick(rng, w["place_by_relation"][relation]).format(x=say(other)), "relation", relation)
    return Fragment(pick(rng, w["place"][key]), "place", key)


def state_fragment(state: str, rng: np.random.Generator) -> Fragment:
    return Fragment(pick(rng, words()["state"][state]), "state", state)


def left_verb(rng: np.random.Generator, plural: bool) -> str:
    return pick(rng, words()["left_plural" if plural else "left"])


def _head(phrase: str) -> str:
    """The noun a phrase is about: 'box' in 'box of leftovers', 'scissors' in 'kitchen scissors'."""
    before = phrase.split(" of ")[0].split()
    return before[-1].lower() if before else ""


def _plural(phrase: str) -> bool:
    last = _head(phrase)
    return last.endswith("s") and not last.endswith(("ss", "us", "is"))


def _a(phrase: str) -> str:
    """'a' or 'an' by sound, 'some' for plurals and mass nouns (some mouldy bread, a USB stick)."""
    words_ = phrase.split()
    if not words_:
        return phrase
    if _plural(phrase) or _head(phrase) in words()["mass_nouns"]:
        return f"some {phrase}"
    first = words_[0]
    if len(first) > 1 and first.isupper():  # an initialism is said letter by letter: an HDMI cable, a USB stick
        return ("an " if first[0] in "AEFHILMNORSX" else "a ") + phrase
    return ("an " if first[:1].lower() in "aeiou" else "a ") + phrase


def _place_in_room(place: str, room: str) -> str:
    """'on the low table in the bedroom, at a child's height': the room goes before a trailing remark."""
    if room in place:
        return place
    head, comma, tail = place.partition(",")
    return f"{head} in the {room}{comma}{tail}"


def _them(text: str, until: str) -> str:
    """A class's fix says 'it'; a plural object at fault is 'they'/'them' (put the pliers away, until
    they rest), up to where the container or support is named: the 'it' after that is the container's
    ('where a child cannot open it')."""
    cut = text.find(until) if until and until in text else len(text)
    head, tail = text[:cut], text[cut:]
    head = re.sub(r"\bit is\b", "they are", head)
    head = re.sub(r"\bit (rests|stands|lies|sits)\b", lambda m: "they " + m.group(1)[:-1], head)
    return re.sub(r"\bit\b", "them", head) + tail


def cap(text: str) -> str:
    return text[:1].upper() + text[1:] if text else text


def fix_words(hc, *, hazard: str, container: str, support: str, part: str) -> str:
    """The class's own fix in this task's words ({part}: the door or drawer that is open)."""
    if not hc.solution:
        return ""
    text = hc.solution.format(hazard=hazard, container=container, support=support, part=part or DOOR)
    if _plural(hazard):
        text = _them(text, container if "{container}" in hc.solution else support)
    return text


def hot_word(kb, obj: str, hc, said: str) -> str:
    """'lit' or 'hot' for a hot object when the class's danger is a burn or a fire and its name does
    not say so already (a lit candle, a hot iron): the danger sentence then has its cause in the scene."""
    info = kb.objects.get(obj)
    if info is None or "hot" not in info.properties:
        return ""
    if not any(w in hc.why.lower() for w in ("burn", "scald", "fire", "hot", "heat")):
        return ""
    if any(w in said.split() for w in ("hot", "lit", "burning", "warm")):
        return ""
    table = words()["hot_said"]
    return table.get(obj, table["default"])


def reason(kb, hc, obj: str) -> str:
    """The class's reason for a task about ``obj`` (``HazardClass.why_for``: its own where one is kept)."""
    info = kb.objects.get(obj)
    return hc.why_for(obj, info.properties if info is not None else ())


def _condition_words(hc) -> str | None:
    """A composed class's dangerous state in words that follow a place ("with its handle sticking
    out"), when the object's own state is not said otherwise: the danger sentence relies on it."""
    if hc.composition is None or not hc.composition.condition:
        return None
    from anomalygen.knowledge.mechanisms import load_mechanisms

    cond = load_mechanisms().conditions.get(hc.composition.condition)
    return cond.words if cond is not None and cond.words.startswith("with ") else None


def describe_fragments(idea, kb, rng: np.random.Generator, *, say, person: str, part: str, state: str, room: str,
                       container: str, support: str) -> list[Fragment]:
    """The description as tagged fragments: the tagged pieces (place, state, danger, fix, person),
    then the sentences built from them (kind ``sentence``, in order)."""
    hc = kb.hazard_classes[idea.class_id]
    w = words()
    hazard = say(idea.hazard)
    articulated = hc.articulation is not None and hc.about_target
    # a fixture whose own state is the hazard (a baby gate left open) is said by its state, not by
    # where it lies: fixtures stand where they belong (data/knowledge/households.json)
    own_state = hc.articulation is not None and hc.articulation.variable == hc.hazard_variable
    fixture = own_state and idea.hazard in load_households().fixtures
    out: list[Fragment] = []
    if articulated or fixture:
        st = state_fragment(state, rng)
        # a switched appliance is on, not its knob; a tap or a door is the part that is open or running
        whole = not part or part in hazard or (state == "on" and part in w["control_parts"])
        owner = f"the {hazard}" if whole else f"the {part} of the {hazard}"
        situation = f"{cap(owner)} in the {room} {st.text}."
        out.append(st)
        p = idea.placement
        if p.other is not None and p.relation == "near" and p.other != idea.hazard:
            # the heater left on beside the curtains: the danger sentence is about what it stands by
            near = Fragment(f"It is right next to the {say(p.other)}.", "relation", "near")
            out.append(near)
            situation += f" {near.text}"
    else:
        quality = "" if own_state else hot_word(kb, idea.hazard, hc, hazard)  # an iron left on: said next
        if quality:
            out.append(Fragment(quality, "quality", "hot"))
            hazard = f"{quality} {hazard}"
        composed = hc.composition.place if hc.composition is not None and not hc.composition.legacy else None
        p = idea.placement
        pl = place_fragment(p.key, composed, p.other, p.relation, rng, say)
        out.append(pl)
        verb = left_verb(rng, _plural(hazard))
        where = _place_in_room(pl.text, room)
        situation = f"{cap(_a(hazard))} {verb} {where}."
        if own_state:
            st = state_fragment(state, rng)  # an iron left on, as well as where it lies
            out.append(st)
            situation += f" It {st.text}."
        elif (cond := _condition_words(hc)) is not None:
            out.append(Fragment(cond, "state", hc.composition.condition))  # a pot with its handle sticking out
            situation = f"{situation[:-1]} {cond}."
    out.append(Fragment(room, "room", idea.room))
    # objects the hazard needs besides its own (the candle whose fumes fill a shut room): said, never clutter
    needed = [c for c, var in zip(idea.co_objects, secondary_variables(hc), strict=False)
              if c not in (idea.hazard, idea.placement.other)]
    # (not said hot: nothing in the task says it is switched on)
    extra = f" There is {_a(say(needed[0]))} in the room too." if needed else ""
    danger = Fragment(reason(kb, hc, idea.hazard), "danger", hc.id)
    at_risk = Fragment(pick(rng, w["at_risk"]).format(person=person, Person=cap(person)), "person", person)
    hazard = say(idea.hazard)  # the fix names the object plainly
    fix_text = fix_words(hc, hazard=hazard, container=container, support=support, part=part)
    fix = Fragment(fix_text, "fix", hc.id)
    out += [danger, at_risk, fix]
    for text in (situation + extra, danger.text, at_risk.text, fix.text):
        if text.strip():
            out.append(Fragment(text.strip(), "sentence", idea.class_id))
    return out
