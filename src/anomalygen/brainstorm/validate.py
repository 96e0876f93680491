"""Checks a TaskProposal against the catalogue and the knowledge base, beyond its pydantic schema.

Schema validation says a proposal is well-formed; these checks say it can be *built*: every object
is a catalogue name, the hazard class exists, the object a placement names is a catalogue name (the
placement's form is the schema's: ``Placement``).
Used for LLM output (the problems go back to the model as a repair prompt) and for a user's own
tasks.jsonl (the problems are reported per line).
"""

from __future__ import annotations

from anomalygen.knowledge import ROOMS, KnowledgeBase
from anomalygen.schema import Placement, TaskProposal


def placement_ok(placement: Placement, names: set[str]) -> bool:
    """A placement on a support kind, or one naming an object of the catalogue."""
    return placement.other is None or placement.other in names


def proposal_problems(p: TaskProposal, kb: KnowledgeBase) -> list[str]:
    """Human-readable problems; empty when the proposal can be built."""
    names = set(kb.objects)
    out: list[str] = []
    about_target = p.hazard_class in kb.hazard_classes and kb.hazard_classes[p.hazard_class].about_target
    # a class about the target itself (a heater left on) takes the object at fault as its target,
    # one of the 44 categories or not
    if p.target_asset not in kb.targets and not (about_target and p.target_asset == p.scenario.hazard_object
                                                  and p.target_asset in kb.objects):
        out.append(f"target_asset '{p.target_asset}' is not one of the 44 target categories")
    if p.hazard_class == "other":
        if not p.hazard_other:
            out.append("hazard_class 'other' needs hazard_other text")
    elif p.hazard_class not in kb.hazard_classes:
        out.append(f"hazard_class '{p.hazard_class}' is unknown (use a knowledge-base class id or 'other')")
    elif kb.hazard_classes[p.hazard_class].category != p.category:
        out.append(f"category '{p.category.value}' does not match class {p.hazard_class} ({kb.hazard_classes[p.hazard_class].category.value})")
    elif about_target and p.scenario.hazard_object != p.target_asset:
        out.append(f"class {p.hazard_class} is about the target itself: scenario.hazard_object "
                   f"'{p.scenario.hazard_object}' must be the target_asset '{p.target_asset}'")
    s = p.scenario
    for label, name in [("scenario.hazard_object", s.hazard_object), ("scenario.container", s.container)]:
        if name is not None and name not in names:
            out.append(f"{label} '{name}' is not a catalogue object")
    out += [f"scenario.co_objects: '{c}' is not a catalogue object" for c in s.co_objects if c not in names]
    out += [f"auxiliary_items: '{a.name}' is not a catalogue object" for a in p.auxiliary_items if a.name not in names]
    out += [f"articulations: '{a.object}' is not a catalogue object" for a in p.articulations if a.object not in names]
    if not placement_ok(s.placement, names):
        out.append(f"scenario.placement '{s.placement}': '{s.placement.other}' is not a catalogue object")
    if s.room not in ROOMS:
        out.append(f"scenario.room '{s.room}' is not one of {', '.join(ROOMS)}")
    return out
