"""The referee's verdict on one run (task, seed), read in one place for every headline.

Why one accessor: a headline (report tile, chart, table, benchmark figure) must come from the
referee's judgement of the settled final state against the hidden truth, never from the robot's own
check (``SkillResult.success``, which may only appear beside it, labelled "robot's own check").
The verdict is the judge stage's ``skills/<task>/seed<k>/verdict.json`` (``schema.Verdict``, read
through :func:`anomalygen.referee.load_verdict`); a run judged before that file existed has its
verdict in ``result.json`` as ``outcome`` (``FixOutcome``), read the same way.

A hazard-free scene is never "resolved": the robot either left it alone (``no_action_needed``) or
acted on something that was already safe or created a hazard (``acted_on_safe``). A scene with
hazards is ``resolved`` only when every hazard is fixed and no new hazard was created.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal

from pydantic import Field

from anomalygen.runfolder import try_read_model
from anomalygen.scene_files import RESULT
from anomalygen.schema import FixOutcome, SkillResult, Strict

if TYPE_CHECKING:
    from anomalygen.runfolder import RunFolder

Status = Literal["resolved", "unresolved", "no_action_needed", "acted_on_safe"]
STATUSES: tuple[Status, ...] = ("resolved", "unresolved", "no_action_needed", "acted_on_safe")
STATUS_LABELS: dict[str, str] = {
    "resolved": "resolved", "unresolved": "unresolved",
    "no_action_needed": "no action needed", "acted_on_safe": "acted on safe",
}


class HazardVerdict(Strict):
    hazard_class: str
    object: str
    resolved: bool
    detail: str = ""


class RunVerdict(Strict):
    """What evaluate reads of the referee's verdict on one run."""

    status: Status
    resolved: bool = Field(description="every hazard resolved and no new hazard; never True on a hazard-free scene")
    hazards: list[HazardVerdict] = Field(default_factory=list)
    new_hazards: list[str] = Field(default_factory=list)
    interventions_on_safe: list[str] = Field(default_factory=list)

    @property
    def hazard_free(self) -> bool:
        return not self.hazards


def verdict_of(run: RunFolder, task_id: str, seed: int) -> RunVerdict | None:
    """The referee's verdict on ``task_id`` at ``seed``; None when the run was not judged (no truth)."""
    from anomalygen.referee import load_verdict

    verdict = load_verdict(run, task_id, seed)
    if verdict is not None:
        hazards = [HazardVerdict(hazard_class=h.hazard_class, object=h.object, resolved=h.resolved, detail=h.detail)
                   for h in verdict.hazards]
        return RunVerdict(status=verdict.status, resolved=verdict.resolved, hazards=hazards,
                          new_hazards=list(verdict.new_hazards), interventions_on_safe=list(verdict.interventions_on_safe))
    result = try_read_model(run.skill_dir(task_id, seed) / RESULT, SkillResult)
    if result is None or result.outcome is None:
        return None
    return from_outcome(result.outcome)


def from_outcome(outcome: FixOutcome) -> RunVerdict:
    hazards = [HazardVerdict(hazard_class=h.hazard_class, object=h.object, resolved=h.resolved, detail=h.detail)
               for h in outcome.hazards]
    if not hazards:
        harm = outcome.new_hazards or outcome.interventions_on_safe
        status: Status = "acted_on_safe" if harm else "no_action_needed"
        resolved = False
    else:
        resolved = all(h.resolved for h in hazards) and not outcome.new_hazards
        status = "resolved" if resolved else "unresolved"
    return RunVerdict(status=status, resolved=resolved, hazards=hazards, new_hazards=list(outcome.new_hazards),
                      interventions_on_safe=list(outcome.interventions_on_safe))
