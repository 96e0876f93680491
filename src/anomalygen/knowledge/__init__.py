"""The household-hazard knowledge base: hazard classes, object knowledge, role profiles, predicates.

Every stage reads hazards through this package so "hazardous", "fixed" and "safe" mean the same
thing in brainstorming, scene building, detection, planning and evaluation.
"""

from anomalygen.knowledge.base import KnowledgeBase, load_kb
from anomalygen.knowledge.models import (
    PROPERTIES,
    RECIPE_ARGS,
    ROOMS,
    SUPPORT_HEIGHTS,
    ArticulationTemplate,
    HazardClass,
    ObjectInfo,
    PartInfo,
    RecipeStep,
    RoleProfile,
)
from anomalygen.schema import HazardCategory

__all__ = [
    "PROPERTIES",
    "RECIPE_ARGS",
    "ROOMS",
    "SUPPORT_HEIGHTS",
    "ArticulationTemplate",
    "HazardCategory",
    "HazardClass",
    "KnowledgeBase",
    "ObjectInfo",
    "PartInfo",
    "RecipeStep",
    "RoleProfile",
    "load_kb",
]
