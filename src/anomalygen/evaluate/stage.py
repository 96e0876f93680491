"""``anomalygen evaluate``: compute every metric of a run into ``evaluation.json`` and print the diversity table.

Works on whatever the run holds: a missing stage leaves its section empty and is listed in ``not_run``.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from anomalygen.evaluate import run_metrics as rm
from anomalygen.evaluate.diversity import diversity_table, rich_table
from anomalygen.evaluate.results import AblationRow, DiversityRow, Evaluation
from anomalygen.evaluate.text_metrics import task_text
from anomalygen.runfolder import RunFolder, now_iso, read_model, write_model
from anomalygen.runner import StageSummary
from anomalygen.schema import StageRecord

if TYPE_CHECKING:
    from anomalygen.config import Settings

EVALUATION_FILE = "evaluation.json"


def evaluation_path(run: RunFolder):
    return run.root / EVALUATION_FILE


def load_evaluation(run: RunFolder) -> Evaluation | None:
    path = evaluation_path(run)
    return read_model(path, Evaluation) if path.is_file() else None


def evaluate_run(run: RunFolder, settings: Settings) -> Evaluation:
    """All metrics of one run, as a typed record (no printing, no writing)."""
    cfg = settings.evaluate
    tasks = rm.load_tasks(run)
    scenes = rm.built_scenes(run)
    detections = rm.load_detections(run)
    results = rm.load_skill_results(run)
    manifest = run.load_manifest()
    timings: dict[str, float] = {}

    renders = rm.scene_renders(run)
    by_mode: dict[str, list[str]] = {}
    engines = {str(t.provenance.engine) for t in tasks}
    group_of: dict[str, tuple[str, str]] = {}  # row label -> (engine, mode)
    for t in tasks:
        engine, mode = str(t.provenance.engine), str(t.provenance.mode)
        label = f"mode={mode}" if len(engines) == 1 else f"engine={engine} mode={mode}"
        group_of[label] = (engine, mode)
        by_mode.setdefault(label, []).append(task_text(t.name, t.description))
    rows = diversity_table(
        run.root.name,
        [task_text(t.name, t.description) for t in tasks],
        renders,
        seed=settings.seed,
        wmd_pairs=cfg.wmd_pairs,
        baselines=cfg.baselines,
        image_metrics=cfg.image_metrics,
        vit_weights=cfg.vit_weights,
        timings=timings,
        groups=by_mode if len(by_mode) > 1 else None,  # brainstorm ablation rows when modes are mixed
    )
    ablation = measured_ablation(run.root.name, rows, group_of)
    not_run = [name for name, present in (
        ("brainstorm", bool(tasks)), ("build", bool(scenes)), ("detect", bool(detections)),
        ("plan", run.plans_dir.is_dir() and any(run.plans_dir.glob("*.json"))), ("learn", bool(results)),
    ) if not present]
    return Evaluation(
        run=run.root.name,
        tasks=len(tasks),
        diversity=rows,
        ablation=ablation,
        categories=rm.category_distribution(tasks),
        classes=rm.class_distribution(tasks),
        target_assets=rm.distribution(t.target_asset for t in tasks),
        scenes_built=sum(1 for s in scenes if s.validation is None or s.validation.ok),
        scenes_failed=len(run.errors("build")),
        detection=(rm.detection_summary(detections, tasks, settings.detect.k, rm.load_manifests(run, tasks))
                   if detections else None),
        success=rm.success_summary(results, tasks, rm.load_verdicts(run)) if results else None,
        hazards=_hazards(run, tasks, settings),
        timings=dict(manifest.stages),
        llm_usage=manifest.llm_usage,
        not_run=not_run,
        wall_s=timings,
    )


def _hazards(run: RunFolder, tasks, settings: Settings):
    """The loop table, when the scenes carry truth manifests (None for runs built before them)."""
    from anomalygen.evaluate.hazard_table import hazard_table

    table = hazard_table(run, [t.id for t in tasks], settings.learn.seeds)
    return table if table.scenes else None


def measured_ablation(run_name: str, rows: list[DiversityRow], group_of: dict[str, tuple[str, str]]) -> list[AblationRow]:
    """Our diversity per (engine, mode): the group rows, or the whole-run row when there is one group."""
    by_name = {r.name: r for r in rows if r.kind == "run"}
    out = []
    for label, (engine, mode) in group_of.items():
        row = by_name.get(run_name) if len(group_of) == 1 else by_name.get(f"{run_name} [{label}]")
        if row is not None:
            out.append(AblationRow(engine=engine, mode=mode, tasks=row.tasks, self_bleu=row.self_bleu, sbert=row.sbert, wmd=row.wmd))
    return out


def run_stage(run: RunFolder, settings: Settings) -> StageSummary:
    from anomalygen.evaluate.judged_detections import judge_detections

    started, record = time.perf_counter(), StageRecord(started=now_iso())
    detections = judge_detections(run, settings)  # scored here, after the robot: detect never reads the task
    evaluation = evaluate_run(run, settings)
    write_model(evaluation_path(run), evaluation)
    if not settings.quiet:
        from rich.console import Console

        Console(width=max(Console().width, 120)).print(rich_table(evaluation.diversity))
        if detections is not None:
            from anomalygen.evaluate.detection_report import print_report

            print_report(detections)
        if evaluation.not_run:
            Console(stderr=True).print(f"not run yet: {', '.join(evaluation.not_run)}", highlight=False)
    summary = StageSummary("evaluate", done=1, wall_s=time.perf_counter() - started)
    summary.results["evaluation"] = str(evaluation_path(run))
    record.finished, record.wall_s, record.done = now_iso(), round(summary.wall_s, 3), 1
    run.record_stage("evaluate", record)
    return summary
