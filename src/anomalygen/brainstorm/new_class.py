"""A hazard class an LLM proposes in the predicate language, when no mechanism covers its hazard.

The model writes preconditions, a fix recipe and success predicates over ``$hazard`` (and
``$container``/``$support``/``$target`` where needed); they are checked against the same vocabulary
as the knowledge base's own classes (``KnowledgeBase.class_problems``: predicates, their arguments,
properties, catalogue names, recipe actions). A valid class gets a stable id, is written to the run
folder (``knowledge/classes.json``) and is then built, detected, planned and judged like any other;
an invalid one goes back to the model with the problems listed.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from anomalygen.knowledge import HazardClass, KnowledgeBase
from anomalygen.knowledge.base import RUN_CLASSES, add_run_classes
from anomalygen.rng import stable_hash
from anomalygen.schema import HazardCategory, Placement, PredicateCall, format_validation_error

ROLE_WORDS = {"$hazard": "the object at fault", "$target": "the articulated object at fault",
              "$container": "where the fix stores it", "$support": "where the fix puts it"}


class LLMStep(BaseModel):
    model_config = ConfigDict(extra="forbid")

    action: str = Field(description="a recipe action: pick, place_inside, place_on, close_joint, switch_off, ...")
    args: dict[str, str] = Field(default_factory=dict)


class LLMClass(BaseModel):
    """A new hazard class in the knowledge base's predicate language."""

    model_config = ConfigDict(extra="forbid")

    name: str = Field(description="the hazard in a few words")
    why: str = Field(description="why it is dangerous, one sentence")
    preconditions: list[PredicateCall] = Field(description="predicate calls that make it true, over $hazard")
    recipe: list[LLMStep] = Field(description="the fix as recipe actions")
    success: list[PredicateCall] = Field(description="predicate calls that hold once it is fixed")


def class_id(raw: LLMClass) -> str:
    """A stable id from the class's content, so the same proposal gets the same id in every run."""
    slug = re.sub(r"[^a-z0-9]+", "_", raw.name.lower()).strip("_")[:40] or "hazard"
    digest = stable_hash("llm-class", raw.model_dump_json()) & 0xFFFFFF
    return f"llm_{slug}_{digest:06x}"


def to_class(raw: LLMClass, kb: KnowledgeBase, *, category: HazardCategory, placement: Placement, target: str,
             container: str | None, support: str | None) -> tuple[HazardClass | None, list[str]]:
    """The proposal as a HazardClass, or (None, problems) against the vocabulary."""
    calls = [*raw.preconditions, *raw.success]
    used = {v for c in calls for v in c.args.values() if isinstance(v, str) and v.startswith("$")}
    used |= {v for s in raw.recipe for v in s.args.values() if v.startswith("$")}
    unknown = sorted(used - set(ROLE_WORDS))
    if unknown:
        return None, [f"new_class: use only the variables {', '.join(ROLE_WORDS)}; not {', '.join(unknown)}"]
    fault = "$target" if "$target" in used and "$hazard" not in used else "$hazard"
    try:
        hc = HazardClass(
            id=class_id(raw), name=raw.name, category=category, paper_class=False, at_risk="the household",
            why=raw.why, severity=0.7, variables={v: ROLE_WORDS[v] for v in sorted(used)}, hazard_variable=fault,
            preconditions=raw.preconditions, recipe=[s.model_dump() for s in raw.recipe], success=raw.success,
            placements=[placement], target_assets=[target] if target in kb.targets else [],
            default_containers=[container] if container and "$container" in used else [],
            default_supports=[support] if support and "$support" in used else [],
            mechanism=raw.name, solution="", success_text="",
        )
    except ValidationError as exc:
        return None, [f"new_class: {format_validation_error(exc)}"]
    problems = [p.replace(f"class {hc.id}", "new_class") for p in kb.class_problems(hc)]
    return (None, problems) if problems else (hc, [])


def save_run_classes(root: str | Path, classes: list[HazardClass]) -> None:
    """Write a run's proposed classes (merged with those already there) and add them to this process."""
    from anomalygen.runfolder import atomic_write_text

    if not classes:
        return
    path = Path(root) / RUN_CLASSES
    known = json.loads(path.read_text(encoding="utf-8")).get("classes", []) if path.is_file() else []
    ids = {c["id"] for c in known}
    known += [hc.model_dump(mode="json") for hc in classes if hc.id not in ids]
    atomic_write_text(path, json.dumps({"classes": known}, indent=1) + "\n")
    add_run_classes(root)
