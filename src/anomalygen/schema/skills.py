"""Stage 4 (plan, learn): plans of sub-tasks with rewards and success predicates, and what executing
them achieved (the robot's own belief and the referee's verdict against the hidden truth).
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from anomalygen.schema.base import Artefact, ScalarArg, Strict
from anomalygen.schema.vocabulary import Engine, PredicateCall, PredicateResult, SkillMethod


class RewardTerm(Strict):
    """One composable reward term. ``kind`` selects the meaning of the other fields."""

    kind: Literal["distance", "joint", "inside", "lifted", "upright", "action_penalty"]
    weight: float = 1.0
    a: str | None = Field(None, description="object/link the term is about (instance or instance:link)")
    b: str | None = Field(None, description="other object, link or region for distance/inside")
    target: float | list[float] | None = Field(None, description="target joint value, height, or position")
    joint: str | None = None
    scale: float = 1.0


class RewardSpec(Artefact):
    mode: Literal["spec", "code"] = "spec"
    terms: list[RewardTerm] = Field(default_factory=list)
    code: str | None = Field(None, description="for mode 'code': source of compute_reward(state) -> float")


class SuccessSpec(Artefact):
    """All predicates must hold (after negation) for success."""

    predicates: list[PredicateCall] = Field(default_factory=list)


class SubTask(Artefact):
    id: str
    description: str
    method: SkillMethod
    primitive: str | None = Field(None, description="grasp, approach, release, move_to, push, pull, ...")
    params: dict[str, ScalarArg | list[float]] = Field(default_factory=dict)
    reward: RewardSpec | None = None
    success: SuccessSpec = Field(default_factory=SuccessSpec)


class DroppedFix(Strict):
    """A detected hazard the planner could not make a fix for (no container it fits, no surface, ...),
    kept beside the plan so reports show what was left unfixed and why, not only what was planned."""

    hazard_class: str
    object: str
    reason: str


class Plan(Artefact):
    task_id: str
    source: Literal["ground_truth", "detected"]
    engine: Engine
    subtasks: list[SubTask]
    success: SuccessSpec
    bindings: dict[str, str] = Field(default_factory=dict)
    dropped: list[DroppedFix] = Field(
        default_factory=list, description="detected hazards left out of the plan, each with the planner's reason")


class SubTaskResult(Strict):
    """One sub-task's execution. ``method`` is the method the plan asked for; ``executed_by`` is the
    skill that actually executed it, as ``method:action`` of the skill registry (``*``: the method's
    skill for any action, as SAC learns whatever the reward asks). They differ when a SAC sub-task
    failed and the primitive of its action ran in its place (``method`` "sac", ``executed_by``
    "primitive:push"). None when no skill executed it: CEM on a wheeled robot, the episode budget
    spent, no skill registered for its action, or a skill that reported "not executed"."""

    id: str
    method: SkillMethod
    success: bool
    steps: int = 0
    wall_s: float = 0.0
    detail: str = ""
    attempts: int = Field(1, ge=1, description="executions of the sub-task: retried when its check failed")
    executed_by: str | None = Field(
        None, description="registry key (method:action) of the skill that executed the sub-task, e.g. "
                          "'sac:switch_off', 'primitive:push'; None when none did"
    )


class HazardOutcome(Strict):
    """One manifest hazard after execution, as the referee judged it on the final scene graph."""

    hazard_class: str
    object: str
    resolved: bool
    detail: str = ""


class FixOutcome(Strict):
    """An old run's hidden-truth verdict, kept readable (new runs: ``schema.Verdict`` in verdict.json)."""

    hazards: list[HazardOutcome] = Field(default_factory=list)
    resolved: bool = Field(description="every manifest hazard is resolved (a hazard-free scene: True)")
    new_hazards: list[str] = Field(
        default_factory=list, description="'class on object' hazards present at the end and not at the start"
    )
    interventions_on_safe: list[str] = Field(
        default_factory=list, description="near-miss objects the robot moved or whose parts it moved"
    )


class SkillResult(Artefact):
    task_id: str
    seed: int
    success: bool = Field(description="the plan's own final condition held (what the robot believes)")
    subtasks: list[SubTaskResult] = Field(default_factory=list)
    final_predicates: list[PredicateResult] = Field(default_factory=list)
    video: str | None = None
    timings: dict[str, float] = Field(default_factory=dict)
    error: str | None = None
    outcome: FixOutcome | None = Field(
        None, description="read only for old runs: the referee's verdict is now written after the robot's items, "
        "by the judge stage, to verdict.json (schema.Verdict); new results leave this None")
