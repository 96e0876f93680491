"""Judging detections after the fact: the text judge's hits against the task, and the truth's scores.

Why on the evaluate side and not in the detect stage: a detector's answer is scored with the answer
key (the hidden task and truth.json), and the robot's side may not read it. The detect stage writes
what the robot claimed; ``anomalygen evaluate`` adds how each claim was judged
(``Detection.judgements``, ``hit_rank``, ``miss_reason``, ``hazard_free``, ``judged``) and writes
``detections_summary.json`` with hit@k and the per-hazard scores against truth.json.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from anomalygen.runfolder import RunFolder, try_read_model, write_jsonl, write_model
from anomalygen.schema import Detection, HazardManifest, LLMUsage, SceneGraph, SceneSpec, TaskProposal

if TYPE_CHECKING:
    from anomalygen.config import Settings


def make_judge(settings: Settings):
    """The text judge: exact for rule and hybrid hypotheses, calibrated SBERT (and an LLM if asked) for free text."""
    from anomalygen.evaluate.text_judge import Judge

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
    from anomalygen.evaluate.text_judge import first_hit, miss_reason
    from anomalygen.referee.ground_truth import ground_truth

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


def judge_detections(run: RunFolder, settings: Settings):
    """Judge every detection of the run that is not judged yet, write it back (and ``detections.jsonl``),
    and write ``detections_summary.json``; returns the ``DetectionReport`` (None: nothing detected)."""
    from anomalygen.detect.stage import detection_path
    from anomalygen.evaluate.detection_report import summarise, summary_path
    from anomalygen.referee.score import score_detections
    from anomalygen.referee.truth import load_manifest

    tasks = run.load_tasks() if run.tasks_path.is_file() else []
    judge, usage, detections = None, LLMUsage(), []
    for t in tasks:
        det = try_read_model(detection_path(run, t.id), Detection)
        if det is None:
            continue
        if not det.judged:
            judge = judge or make_judge(settings)
            scene_dir = run.scene_dir(t.id)
            det = judge_detection(det, t, try_read_model(scene_dir / "scene.json", SceneSpec),
                                  try_read_model(scene_dir / "scene_graph.json", SceneGraph), load_manifest(scene_dir),
                                  judge)
            write_model(detection_path(run, t.id), det)
        detections.append(det)
    if judge is not None and judge.llm is not None:
        usage.add(judge.llm.reset_usage())
    if usage.requests or usage.cache_hits:
        from anomalygen.llm import record_usage

        record_usage(run, usage)
    if not detections:
        return None
    write_jsonl(run.detections_path, detections)
    report = summarise(detections, tasks, settings.detect.k)
    manifests = {t.id: m for t in tasks if (m := load_manifest(run.scene_dir(t.id))) is not None}
    report.scores = score_detections(detections, manifests, settings.detect.k) if manifests else None
    write_model(summary_path(run), report)
    return report
