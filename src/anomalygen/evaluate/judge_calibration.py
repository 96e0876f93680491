"""Calibrate the text judge's Sentence-BERT threshold on the hand-labelled pairs, and report how good it is.

``python -m anomalygen.evaluate.judge_calibration`` embeds every (hypothesis, task) pair of
``data/judge/calibration.jsonl``, picks the threshold with the best F1, prints precision and recall
overall and per kind of pair, and with ``--write`` stores the threshold in ``data/judge/threshold.json``
(which :func:`anomalygen.evaluate.text_judge.calibrated_threshold` reads). Precision and recall are also
reported under leave-one-task-out cross-validation, so the figure is not only a training score.
"""

from __future__ import annotations

import argparse
import json
from collections import defaultdict
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import numpy as np

from anomalygen.evaluate.text_judge import best_threshold, prf


@dataclass(frozen=True)
class Pair:
    id: str
    task_text: str
    hypothesis_text: str
    hit: bool
    kind: str

    @property
    def task_key(self) -> str:
        return self.id.split("h", 1)[0]


def calibration_path() -> Path:
    return Path(str(resources.files("anomalygen.data").joinpath("judge/calibration.jsonl")))


def load_pairs(path: Path | None = None) -> list[Pair]:
    """Read the labelled set; texts are joined exactly as the judge joins them at run time."""
    pairs = []
    for line in (path or calibration_path()).read_text(encoding="utf-8").splitlines():
        if not line.strip():
            continue
        row = json.loads(line)
        t, h = row["task"], row["hypothesis"]
        task_text = ". ".join(s.strip().rstrip(".") for s in (t["name"], t["description"], t["solution"]) if s.strip())
        hyp_text = f"{h['problem'].strip().rstrip('.')}. {h['solution'].strip()}"
        if row["label"] not in ("hit", "miss"):
            raise ValueError(f"{row['id']}: label must be hit or miss")
        pairs.append(Pair(row["id"], task_text, hyp_text, row["label"] == "hit", row["kind"]))
    return pairs


def similarities(pairs: list[Pair]) -> np.ndarray:
    from anomalygen.embedding import embed

    tasks = sorted({p.task_text for p in pairs})
    tvec = dict(zip(tasks, embed(tasks), strict=True))
    hvec = embed([p.hypothesis_text for p in pairs])
    return np.array([float(hvec[i] @ tvec[p.task_text]) for i, p in enumerate(pairs)])


@dataclass
class CalibrationResult:
    threshold: float
    precision: float
    recall: float
    f1: float
    cv_precision: float
    cv_recall: float
    n_pairs: int
    n_hits: int
    per_kind: dict[str, dict[str, float]]

    def as_dict(self) -> dict:
        return {k: (round(v, 4) if isinstance(v, float) else v) for k, v in self.__dict__.items()}


def calibrate(pairs: list[Pair], sims: np.ndarray | None = None) -> CalibrationResult:
    sims = similarities(pairs) if sims is None else sims
    labels = np.array([p.hit for p in pairs])
    t, p, r, f = best_threshold(sims, labels)
    # Leave one task out: each task's pairs are judged with a threshold fitted on the other tasks.
    keys = np.array([p.task_key for p in pairs])
    cv_pred = np.zeros(len(pairs), dtype=bool)
    for key in np.unique(keys):
        held = keys == key
        t_fold = best_threshold(sims[~held], labels[~held])[0]
        cv_pred[held] = sims[held] >= t_fold
    cv_p, cv_r, _ = prf(cv_pred, labels)
    per_kind: dict[str, dict[str, float]] = defaultdict(dict)
    for kind in sorted({p.kind for p in pairs}):
        idx = np.array([p.kind == kind for p in pairs])
        per_kind[kind] = {
            "n": int(idx.sum()),
            "judged_hit_rate": round(float(np.mean(sims[idx] >= t)), 4),
            "mean_similarity": round(float(np.mean(sims[idx])), 4),
        }
    return CalibrationResult(t, p, r, f, cv_p, cv_r, len(pairs), int(labels.sum()), dict(per_kind))


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true", help="store the threshold in data/judge/threshold.json")
    args = ap.parse_args(argv)
    result = calibrate(load_pairs())
    print(json.dumps(result.as_dict(), indent=2))
    if args.write:
        from anomalygen.runfolder import atomic_write_text

        path = calibration_path().with_name("threshold.json")
        payload = {"threshold": round(result.threshold, 4), "precision": round(result.precision, 4),
                   "recall": round(result.recall, 4), "cv_precision": round(result.cv_precision, 4),
                   "cv_recall": round(result.cv_recall, 4), "n_pairs": result.n_pairs,
                   "command": "python -m anomalygen.evaluate.judge_calibration --write"}
        atomic_write_text(path, json.dumps(payload, indent=2) + "\n")
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
