"""Ground every name of one LLM-written proposal before it is validated (issues 15 and 25).

The model writes what it means ("kettle", "cabinet", "household_hazard"); this turns each name into
the knowledge-base name with ``knowledge.grounding.NameGrounder`` and keeps a record of every
resolution, but never reads one thing as another:
- an object found only by retrieval counts only when it is close and clearly ahead of the runner-up
  (``RETRIEVAL_FLOOR``/``RETRIEVAL_MARGIN``): "sofa" is not a chair, it goes back to the model;
- a hazard class is its exact name, else the hazard the proposal's own text states, composed from
  the mechanisms like a user's line (for ``--tasks-text`` the user's line itself); a category word
  ("household_hazard") or "other" is never turned into a class by retrieval: it is composed, or the
  model's own ``new_class``, or goes back to the model;
- a catalogue object written as the target that is no target category keeps its role as the hazard,
  and the class supplies the target;
- "none", "null" and the like mean empty; a room written as an object is context and is dropped.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from anomalygen.brainstorm.llm_reply import LLMProposal
from anomalygen.knowledge.grounding import GENERIC_CLASS_WORDS, NameGrounder, normalise
from anomalygen.schema import GroundingMatch, HazardCategory, Placement

#: Values that mean "no such thing" (an empty container, no co-objects).
EMPTY_WORDS = frozenset({"", "none", "null", "n_a", "na", "nothing", "no", "empty", "no_container", "not_applicable", "nil"})


@dataclass
class GroundedNames:
    hazard_class: str
    hazard_other: str | None
    target_asset: str
    hazard_object: str
    room: str
    placement: Placement | None  # None: the written placement was not grounded (a problem says so)
    container: str | None
    co_objects: list[str]
    matches: list[GroundingMatch] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)
    new_class: object | None = None  # a HazardClass the model proposed, validated
    called: dict[str, str] = field(default_factory=dict)  # catalogue name -> the model's word, for lexicon proxies


def _closest(m: GroundingMatch) -> str:
    shown = m.alternatives[:3]
    return f" (closest: {', '.join(shown)})" if shown else ""


def grounded_placement(m: GroundingMatch) -> Placement | None:
    """The placement a grounded match names (its compact word), None when it was not grounded."""
    return Placement.model_validate(m.grounded) if m.grounded is not None else None


def is_empty(value: str | None) -> bool:
    return value is None or normalise(str(value)) in EMPTY_WORDS


def _object_or_lexicon(g: NameGrounder, written: str, where: str) -> GroundingMatch:
    """The catalogue name for ``written`` by spelling and aliases; else a word of the household lexicon
    as a proxy shape of its kind (``method="lexicon"``, its ``kind`` recorded: the caller keeps the
    written word as the object's name); else Sentence-BERT retrieval."""
    from anomalygen.knowledge.lexicon import load_lexicon

    pool = set(g.objects.names)
    if g.objects.spelled(written, pool) is None:
        reading = load_lexicon().read(written)
        if reading is not None and reading.proxy in pool:
            return GroundingMatch(field=where, written=written, grounded=reading.proxy, method="lexicon",
                                  kind=reading.kind)
    return g.object(written, where)


def ground_llm_names(raw: LLMProposal, g: NameGrounder, *, reader=None) -> GroundedNames:
    """Every name of ``raw`` grounded; unresolved ones keep their written form and add a problem.

    ``reader`` (a ``free_text.TextGrounder``) composes the hazard the proposal's text states."""
    kb = g.kb
    matches: list[GroundingMatch] = []
    problems: list[str] = []

    def keep(m: GroundingMatch) -> str:
        matches.append(m)
        if m.grounded is None:
            problems.append(
                f"{m.field} '{m.written}' matches no catalogue name well enough (similarity {m.similarity:.2f})"
                f"{_closest(m)}; use a name from the lists"
            )
            return m.written
        return m.grounded

    category = getattr(raw.category, "value", raw.category)
    hazard_match = _object_or_lexicon(g, raw.hazard_object, "scenario.hazard_object")
    hazard = keep(hazard_match)
    spelled_target = g.objects.spelled(raw.target_asset, set(kb.objects))
    target = None
    if spelled_target is not None and spelled_target[0] not in kb.targets:
        matches.append(GroundingMatch(field="target_asset", written=raw.target_asset, grounded=None, method="dropped"))
    else:
        target = keep(g.target(raw.target_asset))
    cls, hazard_other, new_class = _hazard_class(raw, g, hazard, str(category), matches, problems, reader)
    hc = kb.hazard_classes.get(cls) or new_class
    if target is None:
        from anomalygen.brainstorm.idea_sampler import class_targets

        about_target = hc is not None and hc.about_target
        options = ([hazard] if hazard and (hazard in kb.targets or about_target) else []) + (class_targets(kb, hc) if hc is not None and hc.id in kb.hazard_classes else [])
        target = options[0] if options else (hc.target_assets[0] if hc is not None and hc.target_assets else "Table")
        matches.append(GroundingMatch(field="target_asset", written=raw.target_asset, grounded=target, method="class_default"))
    room = keep(g.room(raw.room))
    placement_match = g.placement(raw.placement)
    keep(placement_match)
    placement = grounded_placement(placement_match)
    container = None
    if is_empty(raw.container):
        if raw.container is not None:
            matches.append(GroundingMatch(field="scenario.container", written=raw.container, grounded=None, method="dropped"))
    elif g.is_room(raw.container):
        defaults = kb.containers_for(hc, hazard) if hc is not None and hazard in kb.objects else []
        container = defaults[0] if defaults else None
        matches.append(GroundingMatch(field="scenario.container", written=raw.container, grounded=container,
                                      method="class_default" if container else "dropped"))
    else:
        container = keep(g.object(raw.container, "scenario.container"))
    co_objects: list[str] = []
    for c in raw.co_objects:
        if is_empty(c) or g.is_room(c):
            matches.append(GroundingMatch(field="scenario.co_objects", written=c, grounded=None, method="dropped"))
            continue
        name = keep(g.object(c, "scenario.co_objects"))
        if name not in co_objects:
            co_objects.append(name)
    called = {hazard: raw.hazard_object.strip()} if hazard_match.method == "lexicon" else {}
    return GroundedNames(cls, hazard_other, target, hazard, room, placement, container, co_objects, matches, problems,
                         new_class, called)


def _hazard_class(raw: LLMProposal, g: NameGrounder, hazard: str, category: str, matches: list, problems: list,
                  reader) -> tuple[str, str | None, object | None]:
    """(class id, hazard_other, proposed class): exact name, else what the text composes, else the
    model's new class, else retrieval for a specific name; never retrieval for a category word."""
    kb = g.kb
    written = raw.hazard_class
    hit = g.classes.spelled(written, set(kb.hazard_classes))
    if hit is not None:
        matches.insert(0, GroundingMatch(field="hazard_class", written=written, grounded=hit[0], method=hit[1]))
        return hit[0], None, None
    if reader is not None:
        from anomalygen.brainstorm.line_compose import Refused

        text = raw.description
        try:
            _, comp = reader.compose(text)
        except Refused:
            comp = None
        if comp is not None and comp.fault.name == hazard:
            matches.insert(0, GroundingMatch(field="hazard_class", written=written, grounded=comp.hc.id, method="composed",
                                             alternatives=[comp.hc.composition.mechanism]))
            return comp.hc.id, None, None
    if raw.new_class is not None:
        from anomalygen.brainstorm.new_class import to_class

        placement = grounded_placement(g.placement(raw.placement)) or Placement(relation="on", support="floor")
        target = g.target(raw.target_asset).grounded or ""
        container = None if is_empty(raw.container) else g.object(raw.container or "", "new_class").grounded
        hc, bad = to_class(raw.new_class, kb, category=HazardCategory(category), placement=placement, target=target,
                           container=container, support=None)
        if hc is not None:
            matches.insert(0, GroundingMatch(field="hazard_class", written=written, grounded=hc.id, method="composed",
                                             alternatives=["new_class"]))
            return hc.id, None, hc
        problems.extend(bad)
        return written, None, None
    key = normalise(written)
    if key == "other" and raw.hazard_other:  # the model says no class fits, in its own words
        matches.insert(0, GroundingMatch(field="hazard_class", written=written, grounded="other", method="other"))
        return "other", raw.hazard_other, None
    if key in GENERIC_CLASS_WORDS or key in {c.value for c in HazardCategory}:
        matches.insert(0, GroundingMatch(field="hazard_class", written=written, grounded=None, method="refused"))
        problems.append(f"hazard_class '{written}' is a category, not a hazard class, and the text states no hazard the "
                        "mechanisms compose: give a class id from the list, or describe a new one in new_class")
        return written, None, None
    cls = g.hazard_class(written, f"{raw.name}. {raw.description}", category=category,
                         hazard_objects=[hazard] if hazard in kb.objects else [])
    fits = cls.grounded in kb.hazard_classes and hazard in kb.hazard_candidates(kb.hazard_classes[cls.grounded])
    if not fits:  # a retrieved class whose hazard could not be this object would be another hazard
        cls = cls.model_copy(update={"grounded": "other", "method": "other"})
    matches.insert(0, cls)
    if cls.grounded in (None, "other"):
        return "other", raw.hazard_other or raw.explanation or raw.description, None
    return cls.grounded, None, None
