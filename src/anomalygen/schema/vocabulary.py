"""The words the stages share: categories, sources, modes, engines, object roles, skill methods, and
calls of knowledge-base predicates.
"""

from __future__ import annotations

from enum import StrEnum

from pydantic import Field

from anomalygen.schema.base import ScalarArg, Strict


class HazardCategory(StrEnum):
    """The paper's three top-level anomaly categories."""

    HOUSEHOLD_HAZARD = "household_hazard"
    HYGIENE = "hygiene"
    CHILD_SAFETY = "child_safety"


class AssetSource(StrEnum):
    PROCEDURAL = "procedural"
    PARTNET = "partnet"
    PACKAGED = "packaged"
    OBJAVERSE = "objaverse"


class BrainstormMode(StrEnum):
    """Ablation modes of stage 1: no roles/no rounds, roles only, full group brainstorming."""

    PLAIN = "plain"
    ROLEPLAY = "roleplay"
    BRAINSTORM = "brainstorm"


class Engine(StrEnum):
    KNOWLEDGE = "knowledge"
    LLM = "llm"


class ObjectRole(StrEnum):
    """Why an object is in a scene. Only the scene builder and evaluator see this, never detection."""

    TARGET = "target"  # the paper's target asset (one of the 44 categories)
    HAZARD = "hazard"  # the object that constitutes the hazard (may be the target itself)
    CONTAINER = "container"  # where the fix puts the hazard object
    SUPPORT = "support"  # table, counter, shelf the scene stands on
    AUXILIARY = "auxiliary"  # task-relevant extra item
    CLUTTER = "clutter"  # unrelated everyday object


class SkillMethod(StrEnum):
    PRIMITIVE = "primitive"
    SAC = "sac"
    CEM = "cem"


class PredicateCall(Strict):
    """A call of a knowledge-base predicate, e.g. ``on_floor(object=$hazard)``.

    Arguments that start with ``$`` are role variables (``$hazard``, ``$target``, ``$container``)
    bound to scene object names when evaluated; the knowledge base defines the predicate names.
    """

    name: str
    args: dict[str, ScalarArg] = Field(default_factory=dict)
    negate: bool = False


class PredicateResult(Strict):
    call: PredicateCall
    holds: bool
    explanation: str = ""
