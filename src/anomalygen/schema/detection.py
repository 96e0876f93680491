"""Stage 3 (detect): ranked hypotheses about the hazard, and how the referee judged each afterwards."""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from anomalygen.schema.base import Artefact, Strict


class Hypothesis(Artefact):
    rank: int = Field(ge=1)
    problem: str
    solution: str
    target_object: str = Field(description="instance name (or category) of the object at fault")
    hazard_class: str | None = None
    score: float = 0.0
    explanation: str = ""


class Judgement(Strict):
    rank: int
    hit: bool
    method: Literal["exact", "sbert", "llm", "none"]
    similarity: float | None = None
    reason: str = ""


class Detection(Artefact):
    task_id: str
    scene_id: str
    detector: Literal["rules", "llm", "hybrid"]
    hypotheses: list[Hypothesis]
    judgements: list[Judgement] = Field(default_factory=list)
    hit_rank: int | None = Field(None, description="rank of the first hit, None for a miss")
    miss_reason: str | None = None
    error: str | None = None
    hazard_free: bool = Field(
        False, description="the scene's truth lists no hazard: left out of hit@k (it counts in the false-alarm rate)"
    )
    judged: bool = Field(
        False, description="the referee's judge stage has filled judgements, hit_rank, miss_reason and hazard_free"
    )
