"""Detection scored like a detector: hypotheses matched to the hazards in each scene's truth.json.

Why not hit@k alone: hit@k asks whether the one intended hazard is among the top k, which says
nothing about scenes with several hazards, scenes with none, or a detector that cries wolf. Here
every hypothesis is a claim; a claim is a true positive when it names a manifest hazard's object
at fault and does not contradict its class (a claim without a class counts on the object alone).
Per-hazard recall, precision and F1 pool all scenes; hit@k is kept for single-hazard scenes so the
paper's figure stays comparable; hazard-free scenes give the false-alarm rate.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from pydantic import Field

from anomalygen.referee.ground_truth import norm_name
from anomalygen.schema import Detection, HazardManifest, Hypothesis, Strict


class DetectionScores(Strict):
    scenes: int = Field(description="scenes with both a detection and a truth manifest")
    hazards: int = Field(description="manifest hazards over those scenes")
    found: int = Field(description="manifest hazards named by at least one claim")
    claims: int = Field(description="distinct (object, class) hypotheses")
    true_claims: int
    recall: float
    precision: float
    f1: float
    single_hazard_scenes: int = 0
    hit_at_k: dict[int, float] = Field(default_factory=dict, description="on single-hazard scenes only")
    hazard_free_scenes: int = 0
    false_alarm_rate: float | None = Field(None, description="hazard-free scenes with any claim; None without such scenes")


def claim_matches(h: Hypothesis, hazard_object: str, hazard_class: str, category: str) -> bool:
    """Does the hypothesis name this hazard: its object (instance, or category) and no other class?"""
    target = norm_name(h.target_object)
    named = target == norm_name(hazard_object) or (target == norm_name(category) and ":" not in h.target_object)
    return named and (h.hazard_class is None or h.hazard_class == hazard_class)


def score_detections(
    detections: Sequence[Detection], manifests: Mapping[str, HazardManifest], k: int
) -> DetectionScores:
    """Scores over every detection whose task has a manifest (``manifests`` is keyed by task id)."""
    hazards = found = claims = true_claims = 0
    single_ranks: list[int | None] = []
    free = free_alarms = scenes = 0
    for d in detections:
        m = manifests.get(d.task_id)
        if m is None or d.error:
            continue
        scenes += 1
        hyps = _distinct(d.hypotheses)
        claims += len(hyps)
        # a claim is true when it names a hazard's object and a class that holds for it there
        true_claims += sum(1 for h in hyps if any(claim_matches(h, z.object, c, z.category)
                                                   for z in m.hazards for c in (z.hazard_class, *z.also_fires)))
        hazards += len(m.hazards)
        found += sum(1 for z in m.hazards if any(claim_matches(h, z.object, z.hazard_class, z.category)
                                                  for h in hyps))
        if not m.hazards:
            free += 1
            free_alarms += int(bool(hyps))
        elif len(m.hazards) == 1:
            z = m.hazards[0]
            ranks = [h.rank for h in d.hypotheses if claim_matches(h, z.object, z.hazard_class, z.category)]
            single_ranks.append(min(ranks) if ranks else None)
    recall = found / hazards if hazards else 0.0
    precision = true_claims / claims if claims else 0.0
    f1 = 2 * recall * precision / (recall + precision) if recall + precision else 0.0
    n1 = len(single_ranks)
    return DetectionScores(
        scenes=scenes,
        hazards=hazards,
        found=found,
        claims=claims,
        true_claims=true_claims,
        recall=round(recall, 4),
        precision=round(precision, 4),
        f1=round(f1, 4),
        single_hazard_scenes=n1,
        hit_at_k={j: round(sum(1 for r in single_ranks if r is not None and r <= j) / n1, 4) if n1 else 0.0
                  for j in range(1, k + 1)},
        hazard_free_scenes=free,
        false_alarm_rate=round(free_alarms / free, 4) if free else None,
    )


def _distinct(hyps: Sequence[Hypothesis]) -> list[Hypothesis]:
    """One claim per (object, class): a detector repeating itself claims nothing new."""
    seen: set[tuple[str, str | None]] = set()
    out = []
    for h in sorted(hyps, key=lambda h: h.rank):
        key = (norm_name(h.target_object), h.hazard_class)
        if key not in seen:
            seen.add(key)
            out.append(h)
    return out
