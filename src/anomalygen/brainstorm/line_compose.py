"""From a parsed line to the hazard it states, composed from the mechanisms, or a refusal with a reason.

The object at fault is a named object the line does not put after a preposition ("the towel on the
stove": the towel). Every class whose kind admits that object is scored by the evidence the line
gives for the class's place (a relation to a fitting object, or its cue words) and condition (its cue
words); a class whose place or condition the line does not state is not built. The line is never
read as another object or another danger: no fitting class means a refusal naming the closest one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from anomalygen.brainstorm.line_parse import (
    CONTAINER_WORDS,
    Mention,
    ParsedLine,
    gerund_compound,
    relation_before,
)
from anomalygen.knowledge import HazardClass, KnowledgeBase
from anomalygen.knowledge.grounding import NameGrounder
from anomalygen.knowledge.mechanisms import MechanismSet
from anomalygen.schema import RELATION_KINDS, Placement

#: Evidence weights (unitless scores): a relation to a fitting object outweighs cue words, which
#: outweigh a place or condition the class needs no words for.
RELATION_EVIDENCE = 3.0
FAMILY_DISCOUNT = 0.5  # a relation of the place's family (on the rim of a filled bath is near its water)
#: Relations that imply another: what lies on a thing, or at its top, is near it (a hair dryer on the
#: edge of a filled basin). A place keyed to "near" is met by them, a little less strongly than by
#: "near" itself, so a place keyed to "on" wins where the line says exactly that. "In" and "under" are
#: not near: a knife in the crib or a dryer in the cupboard under the sink would be built elsewhere.
RELATION_FAMILY: dict[str, tuple[str, ...]] = {"near": ("on", "at"), "on": ("at",)}
CUE_EVIDENCE = 2.0
DEFAULT_EVIDENCE = 0.3
FIRST_SUBJECT_BONUS = 1.0
UNUSED_RELATION_PENALTY = 1.5
EXTRA_CUE = 0.25  # each further cue word of the same place (a line that dwells on an edge means the edge)
MAX_EXTRA_CUES = 3

#: Words that name a surface, and the placement each gives (an edge word turns it into its edge).
SURFACE_WORDS: tuple[tuple[tuple[str, ...], Placement], ...] = (
    (("coffee table", "side table", "low table", "nightstand", "bedside table", "bedside", "footstool", "ottoman",
      "sofa table", "end table"), Placement(relation="on", support="low_table")),
    (("counter", "countertop", "worktop", "benchtop", "kitchen counter", "work surface", "draining board",
      "breakfast bar", "kitchen island"),
     Placement(relation="on", support="counter")),
    (("table", "desk", "dining table", "kitchen table", "workbench"), Placement(relation="on", support="table")),
    (("shelf", "shelves", "bookshelf", "bookcase", "top shelf", "high shelf"), Placement(relation="on", support="shelf")),
    (("hallway", "corridor", "walkway", "doorway", "middle of the floor", "middle of the room", "path"),
     Placement(relation="walkway")),
    (("floor", "ground", "carpet", "rug", "floorboards", "tiles"), Placement(relation="on", support="floor")),
)
EDGE_WORDS = ("edge", "rim", "brink", "hanging over", "overhanging", "half off", "corner of", "teetering", "lip")


@dataclass
class Composition:
    """The hazard a line states: class, object at fault, the related object, and the evidence used."""

    hc: HazardClass
    fault: Mention
    other: Mention | None
    score: float
    place_words: list[str] = field(default_factory=list)
    condition_words: list[str] = field(default_factory=list)
    assumed: bool = False


class Refused(ValueError):
    """A line that states no hazard the mechanisms can build; the message says why and what is closest."""


def compose_line(p: ParsedLine, kb: KnowledgeBase, ms: MechanismSet, g: NameGrounder) -> Composition:
    """The best-supported composition of the line; raises Refused with the reason and the closest class."""
    for u in ms.unsupported:
        said = p.said(u.cues)
        if said:
            raise Refused(f"{u.reason} (the line says '{said[0]}')")
    subjects = p.subjects() or p.mentions[:1]
    _refuse_unknown_subject(p, subjects, g)
    beneath = next((m for m in p.mentions if m.relation == "under" and m is not subjects[0]
                    and "soft" in kb.objects[m.name].properties and not _hangs(kb, m.name)), None)
    if beneath is not None:  # under a table is on the floor; nothing is built under a rug or a blanket
        raise Refused(f"no mechanism for {subjects[0].name} {beneath.prep} {beneath.name}: nothing can be built under another object")
    options: list[Composition] = []
    near_misses: list[tuple[float, HazardClass, Mention, str]] = []
    for rank, fault in enumerate(subjects):
        for hc in kb.hazard_classes.values():
            if hc.composition is None or fault.name not in kb.hazard_candidates(hc):
                continue
            found, missing = _evidence(p, kb, ms, hc, fault)
            if found is None:
                near_misses.append((hc.severity, hc, fault, missing))
                continue
            found.score += FIRST_SUBJECT_BONUS if rank == 0 else 0.0
            options.append(found)
    if not options:
        raise Refused(_no_mechanism(p, subjects, near_misses, kb))
    return max(options, key=lambda c: (c.score, c.hc.severity, c.hc.id))


def _hangs(kb: KnowledgeBase, name: str) -> bool:
    """A soft thing that hangs on a wall (curtains): under it is beside it, not beneath a cover."""
    from anomalygen.knowledge.households import load_households

    f = load_households().fixtures.get(name)
    return f is not None and f.mount == "wall" and "soft" in kb.objects[name].properties


def _refuse_unknown_subject(p: ParsedLine, subjects: list[Mention], g: NameGrounder) -> None:
    """A line whose subject the catalogue does not know is refused by that word, not read as another."""
    first = subjects[0].start if subjects else len(p.tokens)
    words = [t.removesuffix("'s") for t in p.tokens]
    for at, phrase in p.unknown:
        if at >= first:
            break
        if relation_before(words, at)[0] is not None:
            continue
        ranked = g.objects.ranked(phrase, set(g.kb.objects), 2)
        closest = ", ".join(f"{n} ({s:.2f})" for n, s in ranked)
        raise Refused(f"no object '{phrase}' in the catalogue; closest: {closest}")
    if not subjects:
        raise Refused("names no object of the catalogue")
    head = subjects[0]
    compound = gerund_compound(words, head, _state_words())
    if compound is not None:
        ranked = g.objects.ranked(compound, set(g.kb.objects), 2)
        raise Refused(f"no object '{compound}' in the catalogue; closest: " + ", ".join(f"{n} ({s:.2f})" for n, s in ranked))
    if head.name in CONTAINER_WORDS and words[head.end:head.end + 1] == ["of"]:
        inner = next((ph for at, ph in p.unknown if head.end < at <= head.end + 3), None)
        if inner is not None:  # 'a bottle of cooking oil' is the oil, which the catalogue lacks
            ranked = g.objects.ranked(inner, set(g.kb.objects), 2)
            raise Refused(f"no object '{inner}' in the catalogue; closest: " + ", ".join(f"{n} ({s:.2f})" for n, s in ranked))


def _state_words() -> frozenset[str]:
    """Every word of every condition's cues (burning, running, boiling: states, not compound names)."""
    from anomalygen.knowledge.mechanisms import load_mechanisms

    return frozenset(w for c in load_mechanisms().conditions.values() for cue in c.cues for w in cue.split())


def _evidence(p: ParsedLine, kb: KnowledgeBase, ms: MechanismSet, hc: HazardClass,
              fault: Mention) -> tuple[Composition | None, str]:
    """How strongly the line states ``hc`` with ``fault`` at fault; (None, what is missing) if it does not."""
    comp = hc.composition
    place = ms.places[comp.place]
    score, other, place_words = 0.0, None, []
    if place.relation is not None:
        other, exact = _related(p, kb, hc, fault, place.relation)
        if other is None:
            target = place.relation.category or place.relation.variable or "?"
            return None, f"{place.relation.type} {target.lstrip('$')}"
        score += RELATION_EVIDENCE - (0.0 if exact else FAMILY_DISCOUNT)
        place_words = [other.words]
    elif place.cues:
        place_words = p.said(place.cues) or _placed_as(p, fault, place)
        if not place_words:
            return None, place.words or comp.place
        score += CUE_EVIDENCE + EXTRA_CUE * min(len(place_words) - 1, MAX_EXTRA_CUES)
    else:
        score += DEFAULT_EVIDENCE
    cond_words: list[str] = []
    assumed = False
    if comp.condition:
        cond = ms.conditions[comp.condition]
        cond_words = p.said(cond.cues)
        row = next((c for m in ms.mechanisms if m.id == comp.mechanism for c in m.compositions
                    if c.place == comp.place and c.condition == comp.condition and comp.kind in c.kind.split("|")), None)
        if cond_words:
            score += CUE_EVIDENCE
        elif row is not None and row.assume_condition:
            score += DEFAULT_EVIDENCE
            assumed = True
        else:
            return None, cond.words or comp.condition
    used = {id(other)} if other is not None else set()
    unused = [m for m in p.mentions if m.relation in ("on", "inside", "near") and m is not fault and id(m) not in used
              and m.name not in ("counter", "Table", "shelf") and m.words not in place_words]
    score -= UNUSED_RELATION_PENALTY * len(unused)
    return Composition(hc, fault, other, score, place_words, cond_words, assumed), ""


def _related(p: ParsedLine, kb: KnowledgeBase, hc: HazardClass, fault: Mention,
             relation) -> tuple[Mention | None, bool]:
    """The named object the line relates the fault to in the way the place needs, fitting its
    variable, and whether the line said that very relation (False: one of its family, RELATION_FAMILY)."""
    fits = set(kb.static_candidates(hc, relation.variable)) if relation.variable else {relation.category}
    wanted = relation.type.split("|")
    family = {r for w in wanted for r in RELATION_FAMILY.get(w, ())} - set(wanted)
    loose = None
    for m in p.mentions:
        if m is fault or m.name not in fits:
            continue
        if m.relation in wanted:
            return m, True
        if loose is None and (m.relation in family or ("near" in wanted and m.relation == "under" and _hangs(kb, m.name))):
            loose = m  # (under the curtains is beside them: they hang)
    return loose, False


def _placed_as(p: ParsedLine, fault: Mention, place) -> list[str]:
    """The words of a named object the line puts the fault on or in as one of the place's own placements
    ("a pot on the stovetop" states the hob of ``on:Stove``), when no cue word says the place."""
    return [m.words for m in p.mentions if m is not fault and m.relation in ("on", "inside")
            and any(t.relation == m.relation and t.other == m.name for t in place.placements)]


def _no_mechanism(p: ParsedLine, subjects: list[Mention], near: list, kb: KnowledgeBase) -> str:
    fault = subjects[0]
    related = [m for m in p.mentions if m is not fault and m.relation]
    said = f"{fault.name}" + "".join(f" {m.prep} {m.name}" for m in related[:2])
    if not near:
        props = ", ".join(kb.objects[fault.name].properties) or "no hazard property"
        return f"no mechanism puts a {fault.name} at fault ({props}): '{said}'"
    near.sort(key=lambda t: -t[0])
    _, hc, _, missing = near[0]
    return f"no mechanism for {said}; closest: {hc.id} (needs {missing})"


def placement_for(p: ParsedLine, hc: HazardClass, comp: Composition, ms: MechanismSet) -> tuple[Placement, bool]:
    """The scenario placement the line states for ``comp`` (True), or the class's own first one (False)."""
    place = ms.places[hc.composition.place]
    if comp.other is not None:
        for tpl in place.placements:
            cand = tpl.filled(comp.other.name)
            if cand.other == comp.other.name:
                return cand, True
    for m in p.mentions:  # a legacy class's own holders: sour milk inside the fridge, a fork in the microwave
        if m is comp.fault or m.relation not in ("inside", "on"):
            continue
        cand = Placement(relation=m.relation, other=m.name)
        if cand in hc.placements:
            return cand, True
    surface = None
    for words, kind in SURFACE_WORDS:
        if p.said(words):
            surface = kind
            break
    if surface is not None:
        edge = surface.support in RELATION_KINDS["at_edge"].supports and bool(p.said(EDGE_WORDS))
        wanted = Placement(relation="at_edge", support=surface.support) if edge else surface
        if wanted in hc.placements:
            return wanted, True
        if edge and wanted not in hc.placements and surface in hc.placements:
            return surface, True
        if surface in hc.placements:
            return surface, True
    return hc.placements[0], False
