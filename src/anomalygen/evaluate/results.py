"""The typed result of ``anomalygen evaluate`` (``evaluation.json``), read back by the report.

Every section is optional: a stage that has not run leaves its section ``None`` and the report says
"not run" instead of failing.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from anomalygen.evaluate.hazard_table import HazardTable
from anomalygen.referee.score import DetectionScores
from anomalygen.schema import Artefact, LLMUsage, StageRecord, Strict


class DiversityRow(Strict):
    """One line of the diversity table. ``None`` = not measured for this row."""

    name: str
    kind: Literal["run", "baseline", "paper"]
    tasks: int
    self_bleu: float | None = None
    sbert: float | None = None
    wmd: float | None = None
    image: float | None = None
    clip: float | None = None
    image_embedder: str | None = None


class Rate(Strict):
    n: int = 0
    successes: int = 0

    @property
    def rate(self) -> float:
        return self.successes / self.n if self.n else 0.0


class DetectionSummary(Strict):
    scenes: int
    k: int
    hit_at_k: dict[int, float] = Field(description="k -> fraction of scenes whose first hit has rank <= k")
    errors: int = 0
    by_category: dict[str, dict[int, float]] = Field(default_factory=dict)
    detectors: dict[str, int] = Field(default_factory=dict, description="detector -> scenes it produced")
    by_detector: dict[str, dict[int, float]] = Field(default_factory=dict, description="detector -> hit@k of its scenes")

    @property
    def detector_label(self) -> str:
        from anomalygen.evaluate.detection_report import detector_label

        return detector_label(self.detectors)
    scores: DetectionScores | None = Field(None, description="per-hazard scores against truth.json")


class SuccessSummary(Strict):
    results: int = Field(description="(task, seed) results read")
    tasks: int
    overall: Rate
    by_category: dict[str, Rate] = Field(default_factory=dict)
    by_class: dict[str, Rate] = Field(default_factory=dict)
    by_method: dict[str, Rate] = Field(default_factory=dict, description="sub-task success per skill method")
    errors: int = 0
    resolved: Rate = Field(default_factory=Rate, description="the referee's verdict over runs on scenes with hazards: "
                           "every hazard fixed and no new hazard created")
    resolved_by_class: dict[str, Rate] = Field(default_factory=dict)
    new_hazards: int = Field(0, description="runs that left a hazard the scene did not have at the start")
    on_safe: int = Field(0, description="runs that acted on a near-miss (an object that was already safe)")
    hazard_free_runs: int = Field(0, description="runs judged on scenes that held no hazard (never 'resolved')")
    no_action_needed: int = Field(0, description="of those, runs that left the scene as it was")
    acted_on_safe: int = Field(0, description="of those, runs that acted on a safe object")


class AblationRow(Strict):
    """Our measured diversity of one (engine, brainstorm mode) group of this run's proposals."""

    engine: str
    mode: str
    tasks: int
    self_bleu: float | None = None
    sbert: float | None = None
    wmd: float | None = None


class Evaluation(Artefact):
    run: str
    tasks: int
    diversity: list[DiversityRow] = Field(default_factory=list)
    ablation: list[AblationRow] = Field(default_factory=list, description="measured diversity per engine and mode")
    categories: dict[str, int] = Field(default_factory=dict)
    classes: dict[str, int] = Field(default_factory=dict)
    target_assets: dict[str, int] = Field(default_factory=dict)
    scenes_built: int = 0
    scenes_failed: int = 0
    detection: DetectionSummary | None = None
    success: SuccessSummary | None = None
    hazards: HazardTable | None = Field(None, description="per class: present, detected, planned, resolved (truth)")
    timings: dict[str, StageRecord] = Field(default_factory=dict)
    llm_usage: LLMUsage = Field(default_factory=LLMUsage)
    not_run: list[str] = Field(default_factory=list, description="stages with no artefacts yet")
    wall_s: dict[str, float] = Field(default_factory=dict, description="seconds per metric, for the curious")
