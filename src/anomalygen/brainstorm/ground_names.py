"""Ground every name of one LLM-written proposal before it is validated (issue 15).

The model writes what it means ("kettle", "cabinet", "household_hazard"); this turns each name into
the knowledge-base name with ``knowledge.grounding.NameGrounder`` and keeps a record of every
resolution. A name is reported as a problem (and goes back to the model) only when even retrieval
finds nothing close enough; a room written as an object is dropped as context; a hazard that fits no
class becomes ``other`` with the model's own words kept.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from anomalygen.brainstorm.llm_reply import LLMProposal
from anomalygen.knowledge.grounding import NameGrounder
from anomalygen.schema import GroundingMatch


@dataclass
class GroundedNames:
    hazard_class: str
    hazard_other: str | None
    target_asset: str
    hazard_object: str
    room: str
    placement: str
    container: str | None
    co_objects: list[str]
    matches: list[GroundingMatch] = field(default_factory=list)
    problems: list[str] = field(default_factory=list)


def _closest(m: GroundingMatch) -> str:
    shown = m.alternatives[:3]
    return f" (closest: {', '.join(shown)})" if shown else ""


def ground_llm_names(raw: LLMProposal, g: NameGrounder) -> GroundedNames:
    """Every name of ``raw`` grounded; unresolved ones keep their written form and add a problem."""
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

    context = " ".join(t for t in (raw.hazard_other, raw.name, raw.description, raw.explanation) if t)
    category = getattr(raw.category, "value", raw.category)
    target = keep(g.target(raw.target_asset))
    hazard = keep(g.object(raw.hazard_object, "scenario.hazard_object"))
    cls = g.hazard_class(raw.hazard_class, context, category=str(category), hazard_objects=[hazard] if hazard in kb.objects else [])
    matches.insert(0, cls)
    hazard_class = cls.grounded or "other"
    hazard_other = raw.hazard_other
    if hazard_class == "other":
        hazard_other = raw.hazard_other or raw.explanation or raw.description  # the model's own words
    hc = kb.hazard_classes.get(hazard_class)
    room = keep(g.room(raw.room))
    placement = keep(g.placement(raw.placement))
    container = None
    if raw.container:
        if g.is_room(raw.container):
            defaults = kb.containers_for(hc, hazard) if hc is not None and hazard in kb.objects else []
            container = defaults[0] if defaults else None
            matches.append(
                GroundingMatch(
                    field="scenario.container",
                    written=raw.container,
                    grounded=container,
                    method="class_default" if container else "dropped",
                )
            )
        else:
            container = keep(g.object(raw.container, "scenario.container"))
    co_objects: list[str] = []
    for c in raw.co_objects:
        if g.is_room(c):
            matches.append(GroundingMatch(field="scenario.co_objects", written=c, grounded=None, method="dropped"))
            continue
        name = keep(g.object(c, "scenario.co_objects"))
        if name not in co_objects:
            co_objects.append(name)
    return GroundedNames(hazard_class, hazard_other, target, hazard, room, placement, container, co_objects, matches, problems)
