"""Asset library: procedural articulated assets, household objects, importers, retrieval.

Public API (stable; the scene builder, detection and skills stages build on it)::

    from anomalygen.assets import generate, Asset, AssetJoint, Surface, Cavity, retrieve, catalogue
    asset = generate("Refrigerator", seed=3, size=1.7)
"""

from anomalygen.assets.core import available_names, generate
from anomalygen.assets.model import Asset, AssetJoint, Cavity, Surface
from anomalygen.assets.names import household_names, size_range, target_names
from anomalygen.assets.retrieval import CatalogueEntry
from anomalygen.assets.validate import ValidationResult, validate_asset


def catalogue(variants_per_name: int = 3):
    from anomalygen.assets.retrieval import catalogue as _catalogue

    return _catalogue(variants_per_name)


def retrieve(query: str, k: int = 5, category: str | None = None, *, variants_per_name: int = 3):
    from anomalygen.assets.retrieval import retrieve as _retrieve

    return _retrieve(query, k, category, variants_per_name=variants_per_name)


def from_ref(ref):
    """Rebuild the exact asset an ``AssetRef`` points at."""
    from anomalygen.assets.core import from_ref as _from_ref

    return _from_ref(ref)


__all__ = [
    "Asset",
    "AssetJoint",
    "CatalogueEntry",
    "Cavity",
    "Surface",
    "ValidationResult",
    "validate_asset",
    "available_names",
    "catalogue",
    "from_ref",
    "generate",
    "household_names",
    "retrieve",
    "size_range",
    "target_names",
]
