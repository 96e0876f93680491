"""Counting metrics over a run's artefacts: distributions, the referee's verdicts by class, loaders.

Pure functions of typed artefacts, so they are tested on hand-built runs and reused by the report.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

from anomalygen.evaluate.rate import Rate
from anomalygen.evaluate.results import SuccessSummary, VerdictCounts
from anomalygen.evaluate.verdicts import RunVerdict, verdict_of
from anomalygen.runfolder import RunFolder, read_jsonl, try_read_model
from anomalygen.scene_files import RESULT, SCENE_SPEC, render_file
from anomalygen.schema import Detection, SceneSpec, SkillResult, TaskProposal


def distribution(values: Iterable[str]) -> dict[str, int]:
    """Counts, most common first (ties by name) so tables and pies are stable."""
    counts = Counter(values)
    return dict(sorted(counts.items(), key=lambda kv: (-kv[1], kv[0])))


def category_distribution(tasks: Sequence[TaskProposal]) -> dict[str, int]:
    return distribution(str(t.category) for t in tasks)


def class_distribution(tasks: Sequence[TaskProposal]) -> dict[str, int]:
    return distribution(t.hazard_class for t in tasks)


def success_summary(results: Sequence[SkillResult], tasks: Sequence[TaskProposal],
                    verdicts: Mapping[tuple[str, int], RunVerdict | None]) -> SuccessSummary:
    """The referee's verdicts over every (task, seed) result, by the task's category and hazard class,
    with the robot's own check beside them (``verdicts``: (task id, seed) -> verdict, None if unjudged)."""
    by_id = {t.id: t for t in tasks}
    out = SuccessSummary(results=len(results), tasks=len({r.task_id for r in results}),
                         errors=sum(1 for r in results if r.error))
    by_category: dict[str, VerdictCounts] = {}
    by_class: dict[str, VerdictCounts] = {}
    robot_by_class: dict[str, Rate] = {}
    by_method: dict[str, Rate] = {}
    for r in results:
        task = by_id.get(r.task_id)
        category, hazard_class = (str(task.category), task.hazard_class) if task else ("unknown", "unknown")
        out.class_category[hazard_class] = category
        _bump(out.robot_check, r.success)
        _bump(robot_by_class.setdefault(hazard_class, Rate()), r.success)
        for sub in r.subtasks:
            _bump(by_method.setdefault(str(sub.method), Rate()), sub.success)
        verdict = verdicts.get((r.task_id, r.seed))
        if verdict is None:
            out.unjudged += 1
            continue
        for counts in (out.verdicts, by_category.setdefault(category, VerdictCounts()),
                       by_class.setdefault(hazard_class, VerdictCounts())):
            count_verdict(counts, verdict)
    out.by_category = dict(sorted(by_category.items()))
    out.by_class = dict(sorted(by_class.items()))
    out.robot_check_by_class = dict(sorted(robot_by_class.items()))
    out.by_method = dict(sorted(by_method.items()))
    return out


def count_verdict(counts: VerdictCounts, verdict: RunVerdict) -> None:
    counts.runs += 1
    setattr(counts, verdict.status, getattr(counts, verdict.status) + 1)
    counts.new_hazards += int(bool(verdict.new_hazards))
    counts.on_safe += int(bool(verdict.interventions_on_safe))


def _bump(rate: Rate, ok: bool) -> None:
    rate.n += 1
    rate.successes += int(ok)


# --------------------------------------------------------------------------- reading a run


def load_tasks(run: RunFolder) -> list[TaskProposal]:
    return run.load_tasks() if run.tasks_path.is_file() else []


def load_manifests(run: RunFolder, tasks: Sequence[TaskProposal]) -> dict:
    """Task id -> the builder's truth manifest, for scenes that have one (the answer key: metrics only)."""
    from anomalygen.evaluate.detection_scores import load_manifest

    return {t.id: m for t in tasks if (m := load_manifest(run.scene_dir(t.id))) is not None}


def load_detections(run: RunFolder) -> list[Detection]:
    if run.detections_path.is_file():
        return read_jsonl(run.detections_path, Detection, strict=False)
    if run.detections_dir.is_dir():  # per-item files before the stage merges them
        return [d for p in sorted(run.detections_dir.glob("*.json")) if (d := try_read_model(p, Detection))]
    return []


def load_verdicts(run: RunFolder, results: Sequence[SkillResult]) -> dict[tuple[str, int], RunVerdict | None]:
    """(task id, seed) -> the referee's verdict, for every result read."""
    return {(r.task_id, r.seed): verdict_of(run, r.task_id, r.seed) for r in results}


def load_skill_results(run: RunFolder) -> list[SkillResult]:
    if not run.skills_dir.is_dir():
        return []
    paths = sorted(run.skills_dir.glob(f"*/seed*/{RESULT}"))
    return [r for p in paths if (r := try_read_model(p, SkillResult)) is not None]


def built_scenes(run: RunFolder) -> list[SceneSpec]:
    if not run.scenes_dir.is_dir():
        return []
    return [s for p in sorted(run.scenes_dir.glob(f"*/{SCENE_SPEC}")) if (s := try_read_model(p, SceneSpec))]


def scene_renders(run: RunFolder) -> list[Path]:
    """One front render per built scene (the paper embeds one image per scene)."""
    if not run.scenes_dir.is_dir():
        return []
    return sorted(p for p in run.scenes_dir.glob(f"*/{render_file('front')}") if p.is_file())
