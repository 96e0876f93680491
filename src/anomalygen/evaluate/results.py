"""The typed result of ``anomalygen evaluate`` (``evaluation.json``), read back by the report.

Every section is optional: a stage that has not run leaves its section ``None`` and the report says
"not run" instead of failing.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from anomalygen.evaluate.baselines import PaperRow
from anomalygen.evaluate.detection_report import DetectionReport
from anomalygen.evaluate.hazard_table import HazardTable
from anomalygen.evaluate.rate import Rate
from anomalygen.schema import Artefact, LLMUsage, StageRecord, Strict


class DiversityRow(Strict):
    """One line of the diversity table. ``None`` = not measured for this row.

    Measured rows (``run``, ``baseline``) carry Self-BLEU and SBERT similarity of the set's full task
    descriptions as the mean over repeated draws of ``draw_size`` texts (``evaluate/text_draws.py``),
    with their spread; ``published`` holds the paper's figures for the same set, which public code
    cannot reproduce. A ``paper`` row has only ``published``: the paper's own LLM-engine row, or a
    baseline not measured in this run. Files written before the draws existed still load: their
    ``paper`` rows' figures move into ``published`` and their measured rows read as whole-set figures.
    """

    name: str
    kind: Literal["run", "baseline", "paper"]
    tasks: int = Field(description="texts in the set (a paper row: the paper's task count)")
    self_bleu: float | None = Field(None, description="mean over the draws (whole set in older files)")
    sbert: float | None = Field(None, description="mean pairwise SBERT cosine, mean over the draws")
    self_bleu_std: float | None = Field(None, description="sample standard deviation over the draws")
    sbert_std: float | None = None
    self_bleu_95: tuple[float, float] | None = Field(None, description="2.5 and 97.5 percentiles over the draws")
    sbert_95: tuple[float, float] | None = None
    draw_size: int | None = Field(None, description="texts asked for per draw (k); None: older whole-set figures")
    draws: int | None = Field(None, description="draws measured; 1 when the set has no more than draw_size texts")
    small_set: bool = Field(False, description="fewer texts than draw_size: measured whole, flagged")
    text_field: str | None = Field(None, description="the task field measured (the full description)")
    wmd: float | None = Field(None, description="run rows only, whole set: the brainstorming ablation's WMD")
    image: float | None = None
    clip: float | None = None
    image_embedder: str | None = None
    published: PaperRow | None = Field(None, description="as published; not reproducible from public code")

    @model_validator(mode="before")
    @classmethod
    def _published_from_old_paper_row(cls, data):
        """Older files kept the paper's figures in a ``paper`` row's measured fields."""
        if isinstance(data, dict) and data.get("kind") == "paper" and data.get("published") is None:
            figures = {"self_bleu": data.get("self_bleu"), "sbert": data.get("sbert"), "vit": data.get("image"),
                       "clip": data.get("clip")}
            if all(v is not None for v in figures.values()):
                data = {k: v for k, v in data.items() if k not in ("self_bleu", "sbert", "image", "clip", "image_embedder")}
                data["published"] = {"tasks": data.get("tasks"), **figures}
        return data


class VerdictCounts(Strict):
    """The referee's verdicts over a group of runs (``evaluate/verdicts.py``)."""

    runs: int = Field(0, description="runs the referee judged")
    resolved: int = 0
    unresolved: int = 0
    no_action_needed: int = Field(0, description="hazard-free scenes the robot left alone")
    acted_on_safe: int = Field(0, description="hazard-free scenes the robot acted on or made hazardous")
    new_hazards: int = Field(0, description="runs that left a hazard the scene did not have at the start")
    on_safe: int = Field(0, description="runs that acted on a near-miss (an object that was already safe)")

    @property
    def hazard_runs(self) -> int:
        """Runs on scenes that held a hazard: the denominator of the resolved rate."""
        return self.resolved + self.unresolved

    @property
    def hazard_free_runs(self) -> int:
        return self.no_action_needed + self.acted_on_safe

    @property
    def rate(self) -> float:
        return self.resolved / self.hazard_runs if self.hazard_runs else 0.0


class SuccessSummary(Strict):
    """Headlines from the referee's verdicts; the robot's own check only beside them, labelled."""

    results: int = Field(description="(task, seed) results read")
    tasks: int
    verdicts: VerdictCounts = Field(default_factory=VerdictCounts, description="every class, the referee")
    by_category: dict[str, VerdictCounts] = Field(default_factory=dict)
    by_class: dict[str, VerdictCounts] = Field(default_factory=dict)
    class_category: dict[str, str] = Field(default_factory=dict, description="hazard class -> its category")
    unjudged: int = Field(0, description="results the referee has no verdict on (no truth.json)")
    robot_check: Rate = Field(default_factory=Rate, description="robot's own check: its plan's final condition held")
    robot_check_by_class: dict[str, Rate] = Field(default_factory=dict)
    by_method: dict[str, Rate] = Field(default_factory=dict, description="robot's own check per sub-task method")
    errors: int = 0


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
    detection: DetectionReport | None = Field(None, description="against the truth (also detections_summary.json)")
    success: SuccessSummary | None = None
    hazards: HazardTable | None = Field(None, description="per class: present, detected, planned, resolved (truth)")
    timings: dict[str, StageRecord] = Field(default_factory=dict)
    llm_usage: LLMUsage = Field(default_factory=LLMUsage)
    not_run: list[str] = Field(default_factory=list, description="stages with no artefacts yet")
    wall_s: dict[str, float] = Field(default_factory=dict, description="seconds per metric, for the curious")
