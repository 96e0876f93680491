"""The automatic judge that replaces the paper's three human annotators.

A hypothesis hits when
1. it names the object at fault and the task's hazard class (``exact``); or
2. it is free text (no hazard class, or one from a detector whose class labels are not decisive) and
   its Sentence-BERT similarity to the task text clears a threshold calibrated on the labelled set in
   ``anomalygen/data/judge/calibration.jsonl`` (``sbert``); or
3. an LLM judge, when one is configured, says it describes the same problem (``llm``).

Structured hypotheses from the rule and hybrid detectors carry a knowledge-base class and object, so
for them the exact comparison is decisive: a wrong class on the right object is a miss, however
similar the words are.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Sequence
from importlib import resources

import numpy as np
from pydantic import BaseModel, Field

from anomalygen.referee.ground_truth import GroundTruth, norm_name
from anomalygen.schema import Hypothesis, Judgement, SceneGraph

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


def miss_reason(hyps: Sequence[Hypothesis], judgements: Sequence[Judgement], truth: GroundTruth) -> str:
    """One line that says why a scene was missed, for the report's miss list."""
    if not hyps:
        return f"no hypothesis at all (truth {truth.label})"
    parts = [f"#{j.rank} {j.reason}" for j in judgements[:3]]
    return "; ".join(parts)


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


__all__ = ["Judge", "JudgeReply", "calibrated_threshold", "first_hit", "miss_reason", "best_threshold", "prf", "norm_name"]
