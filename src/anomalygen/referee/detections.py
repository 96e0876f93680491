"""Judging a detection after the fact: the text judge's hits against the task, and the truth's scores.

Why here and not in the detect stage: a detector's answer is scored with the answer key (the hidden
task and truth.json), and the robot's side may not read it. The detect stage writes what the robot
claimed; the referee's judge stage adds how each claim was judged (``Detection.judgements``,
``hit_rank``, ``miss_reason``, ``hazard_free``) and sets ``judged``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from anomalygen.schema import Detection, HazardManifest, SceneGraph, SceneSpec, TaskProposal

if TYPE_CHECKING:
    from anomalygen.config import Settings


def make_judge(settings: Settings):
    """The text judge: exact for rule and hybrid hypotheses, calibrated SBERT (and an LLM if asked) for free text."""
    from anomalygen.referee.text_judge import Judge

    client = None
    if settings.llm.configured and settings.detect.llm_judge:
        from anomalygen.llm import shared_client

        client = shared_client(settings.llm)
    # Rule and hybrid hypotheses name a knowledge-base class, so the exact comparison decides them.
    decisive = settings.detect.detector in ("rules", "hybrid")
    return Judge(threshold=settings.detect.judge_threshold, llm_client=client, structured_decisive=decisive)


def judge_detection(det: Detection, task: TaskProposal, spec: SceneSpec | None, graph: SceneGraph | None,
                    manifest: HazardManifest | None, judge) -> Detection:
    """``det`` with its judgement: hit@k fields against the task, or, on a scene whose truth lists no
    hazard, no hit to rank (every claim there is a false alarm, counted by the truth scorer)."""
    from anomalygen.referee.ground_truth import ground_truth
    from anomalygen.referee.text_judge import first_hit, miss_reason

    failed = f"detector failed: {det.error}" if det.error else None
    if manifest is not None and not manifest.hazards:
        return det.model_copy(update={"judgements": [], "hit_rank": None, "hazard_free": True,
                                      "miss_reason": failed, "judged": True})
    truth = ground_truth(task, spec, graph, hazard_variable=_hazard_variable(task.hazard_class))
    judgements = judge.judge(det.hypotheses, truth, graph)
    hit = first_hit(judgements)
    reason = None if hit is not None else (failed or miss_reason(det.hypotheses, judgements, truth))
    return det.model_copy(update={"judgements": judgements, "hit_rank": hit, "miss_reason": reason,
                                  "hazard_free": False, "judged": True})


def _hazard_variable(class_id: str) -> str | None:
    """The knowledge base's variable for the object at fault of a class (None for unknown classes)."""
    from anomalygen.knowledge import load_kb

    hc = load_kb().hazard_classes.get(class_id)
    return hc.hazard_variable if hc is not None else None
