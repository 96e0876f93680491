"""Stage 1 entry point: write ``tasks.jsonl`` from an engine, or from the user's own file.

Resumable like every stage: an existing, valid tasks.jsonl is kept unless ``force``. The output is
written atomically in one go (proposals of a brainstorm depend on each other, so there is no
meaningful per-item resume), then the category and class distribution is printed.
"""

from __future__ import annotations

import time
from collections import Counter
from pathlib import Path
from typing import TYPE_CHECKING

from anomalygen.errors import UserError
from anomalygen.runfolder import RunFolder, now_iso, read_jsonl_numbered, write_jsonl
from anomalygen.runner import StageSummary
from anomalygen.schema import Engine, StageRecord, TaskProposal

if TYPE_CHECKING:
    from anomalygen.config import Settings

STAGE = "brainstorm"


# How the user's own tasks.jsonl is named in its errors (``brainstorm --tasks FILE``).
TASKS_FILE = "--tasks file"


def load_user_tasks(path: str | Path) -> list[TaskProposal]:
    """A user's tasks.jsonl: schema-checked per line, then checked against the catalogue, ids unique."""
    from anomalygen.brainstorm.validate import proposal_problems
    from anomalygen.knowledge import load_kb

    path = Path(path)
    numbered = read_jsonl_numbered(path, TaskProposal, what=TASKS_FILE)  # a UserError for every malformed line
    if not numbered:
        raise UserError(f"{path}: no tasks in the {TASKS_FILE}, only blank lines; write one TaskProposal per line")
    kb = load_kb()
    problems: list[str] = []
    seen: set[str] = set()
    for lineno, task in numbered:
        if task.id in seen:
            problems.append(f"line {lineno}: duplicate id '{task.id}'")
        seen.add(task.id)
        problems += [f"line {lineno} ({task.id}): {p}" for p in proposal_problems(task, kb)]
    if problems:
        shown = "\n  ".join(problems[:20])
        more = f"\n  ... and {len(problems) - 20} more" if len(problems) > 20 else ""
        raise UserError(f"{path}: {len(problems)} problem(s) with the tasks:\n  {shown}{more}")
    return [task for _, task in numbered]


def check_inputs(settings: Settings) -> None:
    """Read the user's own file (``--tasks`` or ``--tasks-text``), if one is set, before anything is
    written: the CLI calls this before it creates the run folder, so a file that is missing, a folder,
    binary, not UTF-8, over-long in a line or empty ends the command with one line and leaves the run
    folder as it was (no folder, no manifest, no tasks.jsonl). ``run_stage`` reads the file again
    (small, cheap) rather than carrying it through the stage interface."""
    from anomalygen.brainstorm.free_text import read_task_lines

    cfg = settings.brainstorm
    if cfg.tasks_file:
        load_user_tasks(cfg.tasks_file)
    elif cfg.tasks_text:
        read_task_lines(cfg.tasks_text)


def generate(settings: Settings, run: RunFolder | None = None) -> tuple[list[TaskProposal], dict[str, str]]:
    """Proposals from the configured engine, and per-item errors (LLM engine only)."""
    cfg = settings.brainstorm
    engine = settings.engine_for("brainstorm")
    if engine == Engine.LLM:
        from anomalygen.brainstorm.llm_engine import LLMEngine

        llm = LLMEngine.from_settings(settings)
        tasks = llm.run(cfg.n)
        if run is not None:
            _keep_llm_output(run, llm)
        return tasks, llm.errors
    from anomalygen.brainstorm.knowledge_engine import KnowledgeEngine

    eng = KnowledgeEngine(
        seed=settings.seed, mode=cfg.mode, agents=cfg.agents, rounds=cfg.rounds, novelty_threshold=cfg.novelty_threshold
    )
    return eng.run(cfg.n), {}


def tasks_from_text(settings, run: RunFolder | None = None) -> tuple[list[TaskProposal], dict[str, str]]:
    """Proposals from ``brainstorm.tasks_text``: structured by the LLM engine when it is the brainstorm
    engine, else grounded offline by retrieval; per-line errors either way."""
    from anomalygen.brainstorm.free_text import read_task_lines, tasks_from_lines

    lines = read_task_lines(settings.brainstorm.tasks_text)
    if settings.engine_for("brainstorm") == Engine.LLM:
        from anomalygen.brainstorm.llm_engine import LLMEngine

        llm = LLMEngine.from_settings(settings)
        tasks = llm.from_texts(lines)
        if run is not None:
            _keep_llm_output(run, llm)
        return tasks, llm.errors
    from anomalygen.knowledge import load_kb

    return tasks_from_lines(lines, load_kb(), seed=settings.seed)


def _keep_llm_output(run: RunFolder, llm) -> None:
    """The LLM's usage in the manifest, and the classes it proposed in the run's knowledge."""
    from anomalygen.brainstorm.new_class import save_run_classes
    from anomalygen.llm import record_usage

    record_usage(run, llm.client.reset_usage())
    save_run_classes(run.root, llm.new_classes)


def run_stage(run: RunFolder, settings: Settings, *, force: bool = False) -> StageSummary:
    started = time.perf_counter()
    record = StageRecord(started=now_iso())
    summary = StageSummary(STAGE)
    cfg = settings.brainstorm
    errors: dict[str, str] = {}
    if cfg.tasks_file:
        tasks = load_user_tasks(cfg.tasks_file)
        write_jsonl(run.tasks_path, tasks)
        summary.done = len(tasks)
    elif cfg.tasks_text:
        tasks, errors = tasks_from_text(settings, run)
        write_jsonl(run.tasks_path, tasks)
        summary.done = len(tasks)
    elif not force and run.tasks_path.is_file() and _valid_existing(run):
        tasks = run.load_tasks()
        summary.skipped = len(tasks)
    else:
        tasks, errors = generate(settings, run)
        if not tasks:  # every item failed (each error is recorded below); the file stays well-formed
            errors.setdefault("empty", "brainstorming produced no valid proposals")
        write_jsonl(run.tasks_path, tasks)
        summary.done = len(tasks)
        if len(tasks) < cfg.n:
            errors.setdefault("shortfall", f"only {len(tasks)} of {cfg.n} proposals could be made")
    for item_id, reason in errors.items():
        run.record_error(STAGE, item_id, reason)
    summary.errors = dict(errors)
    summary.failed = len(errors)
    summary.results = {"categories": dict(Counter(t.category.value for t in tasks)), "classes": dict(Counter(t.hazard_class for t in tasks))}
    summary.wall_s = time.perf_counter() - started
    record.finished = now_iso()
    record.wall_s = round(summary.wall_s, 3)
    record.done, record.skipped, record.failed = summary.done, summary.skipped, summary.failed
    run.record_stage(STAGE, record)
    if not settings.quiet:
        print_distribution(tasks)
    return summary


def _valid_existing(run: RunFolder) -> bool:
    try:
        return bool(run.load_tasks())
    except UserError:
        return False


def print_distribution(tasks: list[TaskProposal]) -> None:
    """Category and class counts as a rich table on stderr, each class under its own category."""
    from rich.console import Console

    from anomalygen.knowledge import load_kb
    from anomalygen.tables import group_table

    kb = load_kb()
    by_class = Counter((t.category.value, t.hazard_class) for t in tasks)
    by_cat = Counter(t.category.value for t in tasks)
    rows = {cat: [(hc, ["✓" if hc in kb.hazard_classes and kb.hazard_classes[hc].paper_class else "", str(n)])
                  for (c, hc), n in sorted(by_class.items(), key=lambda kv: (-kv[1], kv[0])) if c == cat]
            for cat in sorted(by_cat)}
    totals = {cat: ["", str(n)] for cat, n in by_cat.items()}
    Console(stderr=True).print(group_table(f"{len(tasks)} proposals", ("paper", "count"), rows, totals))
