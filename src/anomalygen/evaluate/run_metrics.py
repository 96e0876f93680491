"""Counting metrics over a run's artefacts: distributions, detection hit@k, success by class (the
referee's verdicts, with the robot's own check beside them).

Pure functions of typed artefacts, so they are tested on hand-built runs and reused by the report.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Sequence
from pathlib import Path

from anomalygen.evaluate.results import DetectionSummary, Rate, SuccessSummary
from anomalygen.runfolder import RunFolder, read_jsonl, try_read_model
from anomalygen.schema import Detection, SceneSpec, SkillResult, TaskProposal, Verdict


def distribution(values: Iterable[str]) -> dict[str, int]:
    """Counts, most common first (ties by name) so tables and pies are stable."""
    counts = Counter(values)
    return dict(sorted(counts.items(), key=lambda kv: (-kv[1], kv[0])))


def category_distribution(tasks: Sequence[TaskProposal]) -> dict[str, int]:
    return distribution(str(t.category) for t in tasks)


def class_distribution(tasks: Sequence[TaskProposal]) -> dict[str, int]:
    return distribution(t.hazard_class for t in tasks)


def hit_at_k(detections: Sequence[Detection], k: int) -> dict[int, float]:
    """Fraction of scenes whose first correct hypothesis has rank <= j, for j = 1..k (errors are misses;
    hazard-free scenes have nothing to hit and are left out)."""
    detections = [d for d in detections if not d.hazard_free]
    n = len(detections)
    return {j: (sum(1 for d in detections if d.hit_rank is not None and d.hit_rank <= j) / n if n else 0.0)
            for j in range(1, k + 1)}


def detection_summary(
    detections: Sequence[Detection], tasks: Sequence[TaskProposal], k: int, manifests=None
) -> DetectionSummary:
    """hit@k over every scene, by category; with ``manifests`` (task id -> truth) per-hazard scores too."""
    from anomalygen.referee.score import score_detections

    k = max([k, *(len(d.hypotheses) for d in detections)]) if detections else k
    category = {t.id: str(t.category) for t in tasks}
    groups: dict[str, list[Detection]] = {}
    by_detector: dict[str, list[Detection]] = {}
    for d in detections:
        groups.setdefault(category.get(d.task_id, "unknown"), []).append(d)
        by_detector.setdefault(d.detector, []).append(d)
    return DetectionSummary(
        scenes=len(detections),
        k=k,
        hit_at_k=hit_at_k(detections, k),
        errors=sum(1 for d in detections if d.error),
        by_category={c: hit_at_k(ds, k) for c, ds in sorted(groups.items())},
        detectors={name: len(ds) for name, ds in sorted(by_detector.items())},
        by_detector={name: hit_at_k(ds, k) for name, ds in sorted(by_detector.items())},
        scores=score_detections(detections, manifests, k) if manifests else None,
    )


def success_summary(results: Sequence[SkillResult], tasks: Sequence[TaskProposal],
                    verdicts: dict[tuple[str, int], Verdict] | None = None) -> SuccessSummary:
    """The robot's own check over every (task, seed) result, grouped by the task's category and hazard
    class, and the referee's verdicts (``verdicts``: (task id, seed) -> Verdict) beside it."""
    by_id = {t.id: t for t in tasks}
    overall = Rate()
    by_category: dict[str, Rate] = {}
    by_class: dict[str, Rate] = {}
    by_method: dict[str, Rate] = {}

    def bump(table: dict[str, Rate], key: str, ok: bool) -> None:
        cell = table.setdefault(key, Rate())
        cell.n += 1
        cell.successes += int(ok)

    resolved = Rate()
    resolved_by_class: dict[str, Rate] = {}
    harm = {"new": 0, "safe": 0, "free": 0, "none": 0, "acted": 0}
    verdicts = verdicts or {}
    from anomalygen.referee.verdict import from_old_outcome

    for r in results:
        task = by_id.get(r.task_id)
        overall.n += 1
        overall.successes += int(r.success)
        bump(by_category, str(task.category) if task else "unknown", r.success)
        bump(by_class, task.hazard_class if task else "unknown", r.success)
        for sub in r.subtasks:
            bump(by_method, str(sub.method), sub.success)
        v = verdicts.get((r.task_id, r.seed))
        if v is None and r.outcome is not None:  # a run judged before verdict.json existed
            v = from_old_outcome(r.task_id, r.seed, r.outcome)
        if v is not None:  # the referee's verdict against truth.json
            harm["new"] += int(bool(v.new_hazards))
            harm["safe"] += int(bool(v.interventions_on_safe))
            if not v.hazards:  # a hazard-free scene is never "resolved"
                harm["free"] += 1
                harm["none"] += int(v.status == "no_action_needed")
                harm["acted"] += int(v.status == "acted_on_safe")
                continue
            resolved.n += 1
            resolved.successes += int(v.resolved)
            bump(resolved_by_class, task.hazard_class if task else "unknown", v.resolved)
    return SuccessSummary(
        resolved=resolved,
        resolved_by_class=dict(sorted(resolved_by_class.items())),
        new_hazards=harm["new"],
        on_safe=harm["safe"],
        hazard_free_runs=harm["free"],
        no_action_needed=harm["none"],
        acted_on_safe=harm["acted"],
        results=len(results),
        tasks=len({r.task_id for r in results}),
        overall=overall,
        by_category=dict(sorted(by_category.items())),
        by_class=dict(sorted(by_class.items())),
        by_method=dict(sorted(by_method.items())),
        errors=sum(1 for r in results if r.error),
    )


# --------------------------------------------------------------------------- reading a run


def load_tasks(run: RunFolder) -> list[TaskProposal]:
    return run.load_tasks() if run.tasks_path.is_file() else []


def load_manifests(run: RunFolder, tasks: Sequence[TaskProposal]) -> dict:
    """Task id -> the builder's truth manifest, for scenes that have one (the answer key: metrics only)."""
    from anomalygen.referee.truth import load_manifest

    return {t.id: m for t in tasks if (m := load_manifest(run.scene_dir(t.id))) is not None}


def load_detections(run: RunFolder) -> list[Detection]:
    if run.detections_path.is_file():
        return read_jsonl(run.detections_path, Detection, strict=False)
    if run.detections_dir.is_dir():  # per-item files before the stage merges them
        return [d for p in sorted(run.detections_dir.glob("*.json")) if (d := try_read_model(p, Detection))]
    return []


def load_verdicts(run: RunFolder) -> dict[tuple[str, int], Verdict]:
    """(task id, seed) -> the referee's verdict, for every judged learn run."""
    from anomalygen.referee.stage import VERDICT_FILE

    if not run.skills_dir.is_dir():
        return {}
    paths = sorted(run.skills_dir.glob(f"*/seed*/{VERDICT_FILE}"))
    return {(v.task_id, v.seed): v for p in paths if (v := try_read_model(p, Verdict)) is not None and v.seed is not None}


def load_skill_results(run: RunFolder) -> list[SkillResult]:
    if not run.skills_dir.is_dir():
        return []
    paths = sorted(run.skills_dir.glob("*/seed*/result.json"))
    return [r for p in paths if (r := try_read_model(p, SkillResult)) is not None]


def built_scenes(run: RunFolder) -> list[SceneSpec]:
    if not run.scenes_dir.is_dir():
        return []
    return [s for p in sorted(run.scenes_dir.glob("*/scene.json")) if (s := try_read_model(p, SceneSpec))]


def scene_renders(run: RunFolder) -> list[Path]:
    """One front render per built scene (the paper embeds one image per scene)."""
    if not run.scenes_dir.is_dir():
        return []
    return sorted(p for p in run.scenes_dir.glob("*/render_front.png") if p.is_file())
