"""What an LLM brainstorming agent writes for one idea (``LLMProposal``), before its names are grounded.

Its own module so that the engine that asks for it (``llm_engine.py``) and the grounding of its names
(``ground_names.py``) both build on it without importing each other.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from anomalygen.brainstorm.new_class import LLMClass
from anomalygen.schema import HazardCategory


class LLMProposal(BaseModel):
    """What an agent writes for one idea: the task format plus grounding in catalogue names."""

    model_config = ConfigDict(extra="forbid")

    name: str = Field(description="short task name")
    explanation: str = Field(description="why this is a hazard, who is at risk")
    description: str = Field(description="the situation in two to four sentences")
    hazard_class: str = Field(description="a hazard class id from the list, or 'other'")
    hazard_other: str | None = Field(None, description="the hazard in words when hazard_class is 'other'")
    category: HazardCategory
    target_asset: str = Field(description="one of the target categories")
    hazard_object: str = Field(description="catalogue name of the object that is the hazard")
    room: str
    placement: str
    person_at_risk: str = ""
    container: str | None = Field(None, description="catalogue name where the robot puts the object, if it does")
    co_objects: list[str] = Field(default_factory=list, description="other catalogue objects in the scene")
    articulated_part: str | None = Field(None, description="joint label involved, e.g. door, drawer, lid, knob")
    part_initial_state: Literal["open", "closed", "on", "off", "other"] | None = None
    solution: str = ""
    success_condition: str = ""
    builds_on: list[str] = Field(default_factory=list, description="ids of other participants' proposals used")
    borrowed: list[str] = Field(default_factory=list, description="what was borrowed: mechanism, location, co_objects, person_at_risk")
    new_class: LLMClass | None = Field(
        None, description="only when no listed class fits: the hazard as a new class in the predicate language"
    )
