"""The one door from evaluate to the answer key's detection scorer and ground truth.

Why one module: detections are scored against the builder's hidden truth on the evaluate side only
(the detect stage writes detections and nothing else). Every evaluate module that needs the scorer,
a scene's truth manifest or the text judge's ground truth imports it from here, so moving the
answer key into its own package changes these imports and nothing else.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from anomalygen.referee.ground_truth import GroundTruth, ground_truth, norm_name
from anomalygen.referee.score import DetectionScores, claim_matches, score_detections
from anomalygen.schema import Detection, HazardManifest, Hypothesis, ManifestHazard
from anomalygen.truth.manifest import load_manifest

__all__ = [
    "DetectionScores", "GroundTruth", "claims_on", "finds", "ground_truth", "load_manifest", "norm_name", "score",
]


def score(detections: Sequence[Detection], manifests: Mapping[str, HazardManifest], k: int) -> DetectionScores:
    """Recall, precision, F1, hit@k on single-hazard scenes and false alarms, against truth.json."""
    return score_detections(detections, manifests, k)


def finds(hyps: Sequence[Hypothesis], hazard: ManifestHazard) -> bool:
    """Does any claim name this truth hazard (its object, and no other class)?"""
    return any(claim_matches(h, hazard.object, hazard.hazard_class, hazard.category) for h in hyps)


def claims_on(hyps: Sequence[Hypothesis], hazard: ManifestHazard) -> list[Hypothesis]:
    """The claims about the hazard's object, whatever class they name (for the confusion table)."""
    return [h for h in hyps if claim_matches(h, hazard.object, h.hazard_class or hazard.hazard_class, hazard.category)]
