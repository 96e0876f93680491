"""Stage 1 (brainstorm): a hazard task proposal, its grounded scenario and where it came from."""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from anomalygen.schema.base import Artefact, Strict
from anomalygen.schema.placement import Placement
from anomalygen.schema.vocabulary import BrainstormMode, Engine, HazardCategory


class Provenance(Strict):
    """Where a proposal came from, so brainstorming can be audited and ablated."""

    engine: Engine
    mode: BrainstormMode
    agent_role: str | None = None
    round: int = Field(1, ge=1)
    builds_on: list[str] = Field(default_factory=list, description="ids of proposals this one borrows from")
    borrowed: list[str] = Field(default_factory=list, description="which aspects were borrowed, e.g. 'location'")
    seed: int | None = None
    model: str | None = None


class AuxiliaryItem(Strict):
    name: str = Field(description="catalogue name of the object, e.g. 'pill_bottle'")
    description: str = ""
    purpose: str = Field("", description="why the object is in the scene")
    relevant: bool = True


class ArticulationUse(Strict):
    """An articulated part the task involves and the state it starts in."""

    object: str = Field(description="catalogue name of the articulated object")
    part: str = Field(description="semantic label of the part: door, drawer, lid, knob, ...")
    function: str = ""
    initial_state: Literal["open", "closed", "on", "off", "other"] = "open"
    target_state: Literal["open", "closed", "on", "off", "other"] = "closed"


class Scenario(Strict):
    """The grounded, machine-readable core of a proposal; the texts are realised from it."""

    hazard_object: str = Field(description="catalogue name of the object that is the hazard")
    room: str = Field(description="kitchen, living_room, bedroom, bathroom, hallway, ...")
    placement: Placement = Field(
        description="where the hazard object is: a relation to a support kind or to another object "
        "(the compact words 'counter_edge', 'inside:Bathtub' read too)"
    )
    person_at_risk: str = ""
    container: str | None = Field(None, description="catalogue name of the safe destination, if the fix stores it")
    co_objects: list[str] = Field(default_factory=list, description="other catalogue objects in the story")
    states: dict[str, list[str]] = Field(
        default_factory=dict,
        description="instance states the scene must show, by catalogue name: {'Sink': ['contains_water'], 'candle': ['lit']}",
    )
    called: dict[str, str] = Field(
        default_factory=dict,
        description="the user's own name for an object built as a proxy shape of its kind, by catalogue name: "
        "{'cleaning_spray': 'oven cleaner'}; the scene shows it under that name",
    )


class GroundingMatch(Strict):
    """How one name an LLM (or a user's free text) wrote was resolved to a knowledge-base name.

    Kept in the artefact so a reader can audit every loose name: what was written, what it became,
    by which step (exact, normalised spelling, alias, Sentence-BERT retrieval, a class default, or
    dropped; for a user's line also the words parsed into an object, state or relation, the hazard
    composed from mechanisms, or refused) and how similar the retrieved match was (1.0 for the
    deterministic steps).
    """

    field: str = Field(description="where the name was written, e.g. 'scenario.container'")
    written: str
    grounded: str | None = Field(None, description="the knowledge-base name; None when the name was dropped")
    method: Literal[
        "exact", "normalised", "alias", "retrieval", "class_default", "other", "dropped", "parsed", "composed", "refused",
        "lexicon",
    ]
    similarity: float = 1.0
    alternatives: list[str] = Field(default_factory=list, description="the next retrieval candidates, best first")
    kind: str | None = Field(None, description="the household lexicon's kind, when the name was read as a proxy of its kind")


class TaskProposal(Artefact):
    """One anomaly scenario (the paper's task format plus the grounding our later stages need)."""

    id: str
    name: str
    explanation: str
    description: str
    category: HazardCategory
    hazard_class: str = Field(description="id of a knowledge-base hazard class, or 'other'")
    hazard_other: str | None = Field(None, description="free text when hazard_class is 'other'")
    target_asset: str = Field(description="one of the 44 target asset categories")
    scenario: Scenario
    auxiliary_items: list[AuxiliaryItem] = Field(default_factory=list)
    articulations: list[ArticulationUse] = Field(default_factory=list)
    solution: str = Field("", description="how the hazard is resolved, in words")
    success_condition: str = Field("", description="the safe end state, in words")
    provenance: Provenance
    grounding: list[GroundingMatch] = Field(default_factory=list, description="loose names resolved to catalogue names")
    source: Literal["engine", "user_text", "user_tasks"] = Field(
        "engine",
        description="who wrote it: a brainstorming engine, a user's plain line (built as stated: no hazard-free "
        "variant, no extra hazard), or a user's tasks.jsonl",
    )
