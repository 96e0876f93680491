"""Stage "judge": the referee's verdict on one execution, judged after the robot has finished.

Why a file of its own (``skills/<task>/seed<k>/verdict.json``) rather than a field of the robot's
``result.json``: the robot writes its result while it acts; the verdict is written afterwards by the
referee, from the settled final state and the hidden truth, so nothing the robot reads or writes can
carry it. Every headline figure counts ``Verdict.resolved`` (or ``status``); the robot's own check
(``SkillResult.success``) may appear only beside it, labelled.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from anomalygen.schema.base import Artefact, Strict

VerdictStatus = Literal["resolved", "unresolved", "no_action_needed", "acted_on_safe"]


class HazardVerdict(Strict):
    """One hazard of the truth manifest at the end of a run."""

    hazard_class: str
    object: str
    source: Literal["intended", "incidental"] | None = Field(None, description="as in truth.json")
    resolved: bool = Field(description="its class's success holds and no hazard class fires on the object")
    still_firing: list[str] = Field(
        default_factory=list, description="hazard classes whose preconditions hold for the object at the end"
    )
    detail: str = ""


class Verdict(Artefact):
    """The referee's judgement of one run's settled final state against the scene's truth.json.

    ``status``: a scene with hazards is ``resolved`` (every hazard resolved and no new hazard) or
    ``unresolved``; a hazard-free scene is never resolved: ``no_action_needed`` when the robot left it
    as it was, ``acted_on_safe`` when it moved a near-miss or created a hazard (``new_hazards``).
    """

    task_id: str
    seed: int | None = Field(None, description="the learn seed; None for a state judged outside a run")
    status: VerdictStatus
    resolved: bool = Field(description="every hazard resolved AND no new hazard created (False for a hazard-free scene)")
    hazards: list[HazardVerdict] = Field(default_factory=list)
    new_hazards: list[str] = Field(
        default_factory=list, description="'class on object' hazards present at the end and not at the start"
    )
    interventions_on_safe: list[str] = Field(
        default_factory=list, description="near-miss objects the robot moved or whose parts it moved"
    )
    released: list[str] = Field(
        default_factory=list, description="objects still held by the suction cup at the end, let go before judging"
    )
    judged_from: Literal["state", "graph"] = Field(
        "state", description="state: the simulator state, released and settled; graph: an old run's final graph as saved"
    )
    settle_s: float = Field(0.0, description="simulated seconds the scene settled after the release")
