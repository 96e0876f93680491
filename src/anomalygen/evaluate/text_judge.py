"""The text judge: a hypothesis against the hidden task's words, kept as a labelled diagnostic only.

Detection is scored against the builder's truth (``evaluate/detection_report.py``); this judge asks
something else — does a hypothesis read like the task description? — and its hit@k appears only as
"text judge vs task description (diagnostic)". It replaced the paper's three human annotators:

A hypothesis hits when
1. it names the object at fault and the task's hazard class (``exact``); or
2. it is free text (no hazard class, or one from a detector whose class labels are not decisive) and
   its Sentence-BERT similarity to the task text clears a threshold calibrated on the labelled set in
   ``anomalygen/data/judge/calibration.jsonl`` (``sbert``); or
3. an LLM judge, when one is configured and ``evaluate.text_judge_llm`` is on, says it describes the
   same problem (``llm``).

Structured hypotheses from the rule and hybrid detectors carry a knowledge-base class and object, so
for them the exact comparison is decisive: a wrong class on the right object is a miss, however
similar the words are.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Mapping, Sequence
from importlib import resources
from typing import TYPE_CHECKING

import numpy as np
from pydantic import BaseModel, Field

from anomalygen.evaluate.detection_report import TextJudgeDiagnostic
from anomalygen.evaluate.detection_scores import GroundTruth
from anomalygen.runfolder import RunFolder, try_read_model
from anomalygen.scene_files import SCENE_GRAPH, SCENE_SPEC
from anomalygen.schema import (
    Detection,
    HazardManifest,
    Hypothesis,
    Judgement,
    SceneGraph,
    SceneSpec,
    TaskProposal,
)

if TYPE_CHECKING:
    from anomalygen.config import Settings

# Used only if the calibration file is missing (a broken install); the calibrated value wins.
_FALLBACK_THRESHOLD = 0.6


@functools.cache
def calibrated_threshold() -> float:
    """The SBERT threshold chosen by ``anomalygen.evaluate.judge_calibration`` and stored with the data."""
    try:
        ref = resources.files("anomalygen.data").joinpath("judge/threshold.json")
        return float(json.loads(ref.read_text(encoding="utf-8"))["threshold"])
    except (FileNotFoundError, KeyError, ValueError, ModuleNotFoundError):
        return _FALLBACK_THRESHOLD


def hypothesis_text(h: Hypothesis) -> str:
    return f"{h.problem.strip().rstrip('.')}. {h.solution.strip()}"


class JudgeReply(BaseModel):
    """What the LLM judge must answer."""

    same_problem: bool = Field(description="true if the hypothesis identifies the same hazard on the same object")
    reason: str = Field("", max_length=300)


_JUDGE_SYSTEM = (
    "You grade a household robot's hazard reports. You see the true hazard of a scene and one report. "
    "Answer same_problem=true only if the report points at the same object and the same kind of danger, "
    "even if its wording or its fix differs; a different object or a different danger is false."
)


class Judge:
    """Judges ranked hypotheses against one scene's ground truth."""

    def __init__(self, *, threshold: float | None = None, llm_client=None, structured_decisive: bool = True):
        self.threshold = calibrated_threshold() if threshold is None else threshold
        self.llm = llm_client
        self.structured_decisive = structured_decisive

    def judge(self, hyps: Sequence[Hypothesis], truth: GroundTruth, graph: SceneGraph | None = None) -> list[Judgement]:
        out: list[Judgement] = []
        free: list[int] = []
        for i, h in enumerate(hyps):
            obj_ok = truth.names_object(h.target_object, graph)
            cls_ok = h.hazard_class is not None and h.hazard_class == truth.hazard_class
            if obj_ok and cls_ok:
                out.append(Judgement(rank=h.rank, hit=True, method="exact", reason=f"names {h.target_object} and {h.hazard_class}"))
                continue
            reason = _structured_reason(h, truth, obj_ok, cls_ok)
            out.append(Judgement(rank=h.rank, hit=False, method="exact" if h.hazard_class else "none", reason=reason))
            if h.hazard_class is None or not self.structured_decisive:
                free.append(i)
        if free:
            sims = self._similarities([hyps[i] for i in free], truth)
            for i, sim in zip(free, sims, strict=True):
                j = out[i]
                if sim >= self.threshold:
                    out[i] = Judgement(rank=j.rank, hit=True, method="sbert", similarity=round(sim, 4),
                                       reason=f"text similarity {sim:.2f} >= {self.threshold:.2f}")
                else:
                    out[i] = Judgement(rank=j.rank, hit=False, method="sbert", similarity=round(sim, 4),
                                       reason=f"{j.reason}; text similarity {sim:.2f} < {self.threshold:.2f}")
                    if self.llm is not None:
                        out[i] = self._ask_llm(hyps[i], truth, out[i])
        return out

    def _similarities(self, hyps: Sequence[Hypothesis], truth: GroundTruth) -> list[float]:
        from anomalygen.embedding import embed

        vecs = embed([truth.text] + [hypothesis_text(h) for h in hyps])
        return [float(x) for x in (vecs[1:] @ vecs[0])]

    def _ask_llm(self, h: Hypothesis, truth: GroundTruth, previous: Judgement) -> Judgement:
        from anomalygen.llm import LLMItemError

        user = (
            f"True hazard: {truth.text}\nObject at fault: {truth.label}\n\n"
            f"Report: problem: {h.problem}\nsolution: {h.solution}\nobject: {h.target_object}\n"
            "Does the report identify the same hazard?"
        )
        try:
            reply = self.llm.complete(
                [{"role": "system", "content": _JUDGE_SYSTEM}, {"role": "user", "content": user}], schema=JudgeReply
            )
        except LLMItemError as exc:
            return previous.model_copy(update={"reason": f"{previous.reason}; LLM judge failed: {exc}"})
        if reply.same_problem:
            return Judgement(rank=h.rank, hit=True, method="llm", similarity=previous.similarity,
                             reason=f"LLM judge: {reply.reason}".strip())
        return previous.model_copy(update={"reason": f"{previous.reason}; LLM judge: no ({reply.reason})"})


def _structured_reason(h: Hypothesis, truth: GroundTruth, obj_ok: bool, cls_ok: bool) -> str:
    said = f"{h.target_object}/{h.hazard_class or 'free text'}"
    if h.hazard_class is None:
        return f"{said}: free text" + ("" if obj_ok else f", other object than {truth.label}")
    if obj_ok:
        return f"{said}: right object, wrong class (truth {truth.hazard_class})"
    if cls_ok:
        return f"{said}: right class, wrong object (truth {truth.label})"
    return f"{said}: other object and class (truth {truth.label})"


def first_hit(judgements: Sequence[Judgement]) -> int | None:
    ranks = [j.rank for j in judgements if j.hit]
    return min(ranks) if ranks else None


def best_threshold(sims: np.ndarray, labels: np.ndarray) -> tuple[float, float, float, float]:
    """Threshold maximising F1 over the labelled pairs: (threshold, precision, recall, f1).

    Candidate thresholds are midpoints between sorted similarities, so the choice does not sit on a
    training point; ties in F1 go to the higher threshold (fewer false hits).
    """
    order = np.unique(np.round(sims, 6))
    cands = np.concatenate([[order[0] - 1e-3], (order[:-1] + order[1:]) / 2, [order[-1] + 1e-3]])
    best = (float(cands[0]), 0.0, 0.0, -1.0)
    for t in cands:
        p, r, f = prf(sims >= t, labels)
        if f > best[3] or (f == best[3] and t > best[0]):
            best = (float(t), p, r, f)
    return best


def prf(pred: np.ndarray, labels: np.ndarray) -> tuple[float, float, float]:
    tp = int(np.sum(pred & labels))
    fp = int(np.sum(pred & ~labels))
    fn = int(np.sum(~pred & labels))
    p = tp / (tp + fp) if tp + fp else 0.0
    r = tp / (tp + fn) if tp + fn else 0.0
    f = 2 * p * r / (p + r) if p + r else 0.0
    return p, r, f




# --------------------------------------------------------------------------- the diagnostic over a run


def make_judge(settings: Settings, detector: str) -> Judge:
    """The text judge for detections of ``detector``; the LLM judge only when asked for and configured."""
    client = None
    if settings.llm.configured and settings.evaluate.text_judge_llm:
        from anomalygen.llm import shared_client

        client = shared_client(settings.llm)
    # Rule and hybrid hypotheses name a knowledge-base class, so the exact comparison decides them.
    return Judge(threshold=settings.evaluate.text_judge_threshold, llm_client=client,
                 structured_decisive=detector in ("rules", "hybrid"))


def text_judge_diagnostic(run: RunFolder, detections: Sequence[Detection], tasks: Sequence[TaskProposal],
                          manifests: Mapping[str, HazardManifest], k: int, settings: Settings) -> TextJudgeDiagnostic:
    """hit@1..k of the text judge over the scenes that hold a hazard (a scene without truth.json counts
    as holding its task's hazard), per detector, and how the first hits were judged."""
    from anomalygen.evaluate.detection_scores import ground_truth
    from anomalygen.knowledge import load_kb

    kb = load_kb()
    by_task = {t.id: t for t in tasks}
    judges: dict[str, Judge] = {}
    ranks: dict[str, list[int | None]] = {}
    methods: dict[str, int] = {}
    for d in detections:
        task, truth = by_task.get(d.task_id), manifests.get(d.task_id)
        if task is None or (truth is not None and not truth.hazards):
            continue
        if d.detector not in judges:
            judges[d.detector] = make_judge(settings, d.detector)
        judge = judges[d.detector]
        spec = try_read_model(run.scene_dir(d.task_id) / SCENE_SPEC, SceneSpec)
        graph = try_read_model(run.scene_dir(d.task_id) / SCENE_GRAPH, SceneGraph)
        hc = kb.hazard_classes.get(task.hazard_class)
        truth_of_task = ground_truth(task, spec, graph, hazard_variable=hc.hazard_variable if hc else None)
        judgements = judge.judge(d.hypotheses, truth_of_task, graph)
        hit = first_hit(judgements)
        ranks.setdefault(d.detector, []).append(hit)
        if hit is not None:
            method = next(j.method for j in judgements if j.rank == hit)
            methods[method] = methods.get(method, 0) + 1
    every = [r for rs in ranks.values() for r in rs]
    return TextJudgeDiagnostic(scenes=len(every), hit_at_k=_hit_at_k(every, k),
                               by_detector={name: _hit_at_k(rs, k) for name, rs in sorted(ranks.items())},
                               methods=dict(sorted(methods.items())))


def _hit_at_k(ranks: Sequence[int | None], k: int) -> dict[int, float]:
    n = len(ranks)
    return {j: round(sum(1 for r in ranks if r is not None and r <= j) / n, 4) if n else 0.0 for j in range(1, k + 1)}
