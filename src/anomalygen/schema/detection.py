"""Stage 3 (detect): ranked hypotheses about the hazards of a scene.

Scoring happens on the evaluate side against the scene's truth; the judging fields of ``Detection``
are kept only so detections written before that still read (the detect stage no longer fills them).
"""

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
    error: str | None = None
    judgements: list[Judgement] = Field(default_factory=list, description="legacy, not written any more")
    hit_rank: int | None = Field(None, description="legacy, not written any more")
    miss_reason: str | None = Field(None, description="legacy, not written any more")
    hazard_free: bool = Field(False, description="legacy, not written any more")
