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


class PerceptionNoise(Strict):
    """The perception noise the detector's scene graph went through (``detect.noise``), and what it did.

    Counts only, never which object or its true category: the plan stage reads this file."""

    pose_jitter: float = Field(description="m: bound of each object's position error, per axis (uniform)")
    miss_rate: float = Field(description="chance that a small object was not seen")
    small_size: float = Field(description="m: largest extent at or below which an object counts as small")
    confusion_rate: float = Field(description="chance that an object with look-alikes was seen as one of them")
    seed: int = Field(description="run seed the scene's noise generator was derived from")
    objects: int = Field(0, description="objects in the perfect graph")
    missed: int = Field(0, description="objects left out of the detector's graph")
    confused: int = Field(0, description="objects the detector's graph gives another category")


class Detection(Artefact):
    task_id: str
    scene_id: str
    detector: Literal["rules", "llm", "hybrid", "agent"] = Field(
        description="agent: what an agent of the skill-level env reported (anomalygen bench)")
    hypotheses: list[Hypothesis]
    error: str | None = None
    judgements: list[Judgement] = Field(default_factory=list, description="legacy, not written any more")
    hit_rank: int | None = Field(None, description="legacy, not written any more")
    miss_reason: str | None = Field(None, description="legacy, not written any more")
    hazard_free: bool = Field(False, description="legacy, not written any more")
    noise: PerceptionNoise | None = Field(None, description="perception noise on the detector's graph; None: the perfect graph")
