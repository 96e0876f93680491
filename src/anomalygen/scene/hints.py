"""Scene hints: what an engine other than the random draws says about a scene's objects.

The LLM scene engine (``scene/llm_engine.py``, the paper's scene stage) decides auxiliary objects, each
object's size and its floor position; the builder then uses those instead of its random draws and
records every correction it had to make (a size outside the generator's range, a spot that overlapped)
as a ``ValidationCheck``, so the scene's validation report says where each number came from. Without
hints the builder behaves exactly as before.
"""

from __future__ import annotations

import numpy as np
from pydantic import Field

from anomalygen.schema import Artefact, GroundingMatch, ValidationCheck


class SceneHints(Artefact):
    """Per-catalogue-name sizes and positions, plus the auxiliary objects to dress the scene with."""

    engine: str = "llm"
    model: str | None = None
    sizes: dict[str, float] = Field(default_factory=dict, description="catalogue name -> largest dimension, m")
    positions: dict[str, tuple[float, float]] = Field(
        default_factory=dict, description="catalogue name -> (x, y) in unit-cube coordinates (task objects in 0..1)"
    )
    auxiliaries: list[str] = Field(default_factory=list, description="catalogue names retrieved for the LLM's auxiliary objects")
    grounding: list[GroundingMatch] = Field(default_factory=list)
    checks: list[ValidationCheck] = Field(default_factory=list, description="corrections made before building")

    def size_for(self, catalogue: str) -> float | None:
        return self.sizes.get(catalogue)

    def world_xy(self, catalogue: str) -> np.ndarray | None:
        """The floor position of a unit-cube proposal (the layout's own mapping)."""
        from anomalygen.scene.layout import REGION_ORIGIN, REGION_SIZE

        uv = self.positions.get(catalogue)
        return None if uv is None else REGION_ORIGIN[:2] + np.asarray(uv, float) * REGION_SIZE[:2]

    def note(self, name: str, detail: str, *, value: float | None = None, limit: float | None = None) -> None:
        """Record one correction (it passed: the scene was repaired, not rejected)."""
        self.checks.append(ValidationCheck(name=name, passed=True, value=value, limit=limit, detail=detail))
