"""The data model: one pydantic class per artefact that crosses a stage.

Every artefact is a file in the run folder, so each class is strict (unknown fields are errors, not
silently dropped) and carries a ``schema_version`` so old runs can be detected rather than misread.
Stages depend on these classes, never on each other's internals. One module per stage owns its
artefacts (``tasks``, ``scenes``, ``detection``, ``skills``, ``verdicts``, ``run``) over the shared ``base`` and
``vocabulary``; import every name from ``anomalygen.schema``.
"""

from __future__ import annotations

from pydantic import BaseModel

from anomalygen.schema.base import (
    SCHEMA_VERSION,
    Artefact,
    Quat,
    ScalarArg,
    Strict,
    Vec3,
    format_validation_error,
)
from anomalygen.schema.detection import (
    Detection,
    Hypothesis,
    Judgement,
)
from anomalygen.schema.run import (
    ItemError,
    LLMUsage,
    RunManifest,
    StageRecord,
)
from anomalygen.schema.scenes import (
    CHILD_REACH,
    CLOSED_TOL,
    CLOSURE_LABELS,
    ENCLOSING_LABELS,
    GATE_LABELS,
    LATCHING_PROPERTY,
    SWINGING_CLOSURES,
    SWITCH_LABELS,
    AssetRef,
    GraphObject,
    HazardManifest,
    JointState,
    ManifestHazard,
    NearMiss,
    PlacedCavity,
    PlacedObject,
    Relation,
    SceneGraph,
    SceneSpec,
    ValidationCheck,
    ValidationReport,
    within_child_reach,
)
from anomalygen.schema.skills import (
    FixOutcome,
    HazardOutcome,
    Plan,
    RewardSpec,
    RewardTerm,
    SkillResult,
    SubTask,
    SubTaskResult,
    SuccessSpec,
)
from anomalygen.schema.tasks import (
    ArticulationUse,
    AuxiliaryItem,
    GroundingMatch,
    Provenance,
    Scenario,
    TaskProposal,
)
from anomalygen.schema.verdicts import HazardVerdict, Verdict, VerdictStatus
from anomalygen.schema.vocabulary import (
    AssetSource,
    BrainstormMode,
    Engine,
    HazardCategory,
    ObjectRole,
    PredicateCall,
    PredicateResult,
    SkillMethod,
)

ARTEFACTS: dict[str, type[BaseModel]] = {
    cls.__name__: cls
    for cls in (
        TaskProposal,
        AssetRef,
        PlacedObject,
        JointState,
        SceneSpec,
        HazardManifest,
        SceneGraph,
        Hypothesis,
        Detection,
        SubTask,
        Plan,
        RewardSpec,
        SuccessSpec,
        SkillResult,
        Verdict,
        RunManifest,
        ItemError,
    )
}

__all__ = [
    "SCHEMA_VERSION",
    "Vec3",
    "Quat",
    "ScalarArg",
    "Artefact",
    "Strict",
    "format_validation_error",
    "HazardCategory",
    "AssetSource",
    "BrainstormMode",
    "Engine",
    "ObjectRole",
    "SkillMethod",
    "PredicateCall",
    "PredicateResult",
    "Provenance",
    "AuxiliaryItem",
    "ArticulationUse",
    "Scenario",
    "GroundingMatch",
    "TaskProposal",
    "AssetRef",
    "CLOSURE_LABELS",
    "ENCLOSING_LABELS",
    "SWINGING_CLOSURES",
    "GATE_LABELS",
    "SWITCH_LABELS",
    "CLOSED_TOL",
    "CHILD_REACH",
    "LATCHING_PROPERTY",
    "within_child_reach",
    "JointState",
    "PlacedCavity",
    "PlacedObject",
    "ValidationCheck",
    "ValidationReport",
    "SceneSpec",
    "ManifestHazard",
    "NearMiss",
    "HazardManifest",
    "GraphObject",
    "Relation",
    "SceneGraph",
    "Hypothesis",
    "Judgement",
    "Detection",
    "RewardTerm",
    "RewardSpec",
    "SuccessSpec",
    "SubTask",
    "Plan",
    "SubTaskResult",
    "HazardOutcome",
    "FixOutcome",
    "SkillResult",
    "HazardVerdict",
    "Verdict",
    "VerdictStatus",
    "StageRecord",
    "LLMUsage",
    "RunManifest",
    "ItemError",
    "ARTEFACTS",
]
