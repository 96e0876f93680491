"""``anomalygen evaluate``: compute every metric of a run into ``evaluation.json`` and print the tables.

Works on whatever the run holds: a missing stage leaves its section empty and is listed in ``not_run``.
This is where the robot's work is scored, after its items finished: detections against each scene's
truth (also written as ``detections_summary.json``), runs by the referee's verdict. Tables go to
stderr; stdout stays free for ``--json``.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

from anomalygen.evaluate import run_metrics as rm
from anomalygen.evaluate.diversity import diversity_table, rich_table
from anomalygen.evaluate.results import AblationRow, DiversityRow, Evaluation
from anomalygen.evaluate.text_draws import set_texts
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
    manifests = rm.load_manifests(run, tasks)
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
        by_mode.setdefault(label, []).extend(set_texts([t]))
    rows = diversity_table(
        run.root.name,
        set_texts(tasks),
        renders,
        seed=settings.seed,
        wmd_pairs=cfg.wmd_pairs,
        draw_size=cfg.draw_size,
        draws=cfg.draws,
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
        detection=_detection(run, detections, tasks, manifests, settings) if detections else None,
        success=rm.success_summary(results, tasks, rm.load_verdicts(run, results)) if results else None,
        hazards=_hazards(run, tasks, settings),
        timings=dict(manifest.stages),
        llm_usage=manifest.llm_usage,
        not_run=not_run,
        wall_s=timings,
    )


def _detection(run: RunFolder, detections, tasks, manifests, settings: Settings):
    """Detections scored against the truth, with the text judge's diagnostic beside them."""
    from anomalygen.evaluate.detection_report import summarise
    from anomalygen.evaluate.text_judge import text_judge_diagnostic
    from anomalygen.knowledge import load_kb

    kb = load_kb()
    report = summarise(detections, tasks, manifests, settings.detect.k,
                       category_of={c: str(h.category) for c, h in kb.hazard_classes.items()})
    report.text_judge = text_judge_diagnostic(run, detections, tasks, manifests, report.k, settings)
    return report


def _hazards(run: RunFolder, tasks, settings: Settings):
    """The loop table, when the scenes carry truth manifests (None for runs built before them)."""
    from anomalygen.evaluate.hazard_table import hazard_table

    table = hazard_table(run, [t.id for t in tasks], settings.learn.seeds)
    return table if table.scenes else None


def print_scores(evaluation: Evaluation, console) -> None:
    """Detection against the truth, then the referee's verdicts by category and class."""
    from anomalygen.evaluate.detection_report import print_report
    from anomalygen.evaluate.verdict_table import verdict_table

    if evaluation.detection is not None:
        print_report(evaluation.detection, console=console)
    if evaluation.success is not None:
        console.print(verdict_table(evaluation.success))


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
    started, record = time.perf_counter(), StageRecord(started=now_iso())
    evaluation = evaluate_run(run, settings)
    write_model(evaluation_path(run), evaluation)
    if evaluation.detection is not None:
        from anomalygen.evaluate.detection_report import summary_path

        write_model(summary_path(run), evaluation.detection)
    if not settings.quiet:
        from rich.console import Console

        console = Console(stderr=True)
        console.print(rich_table(evaluation.diversity))
        print_scores(evaluation, console)
        if evaluation.not_run:
            console.print(f"not run yet: {', '.join(evaluation.not_run)}", highlight=False)
    summary = StageSummary("evaluate", done=1, wall_s=time.perf_counter() - started)
    summary.results["evaluation"] = str(evaluation_path(run))
    record.finished, record.wall_s, record.done = now_iso(), round(summary.wall_s, 3), 1
    run.record_stage("evaluate", record)
    return summary
