"""``anomalygen run``: every stage in order, each through its own ``run_stage``, resumable per item.

The pipeline owns no stage logic. It calls brainstorm → build → detect → plan → learn → judge →
evaluate → report (the order of ``anomalygen.stages.STAGES``, the same list the CLI reads); each stage skips
items whose outputs already exist (``anomalygen.runner``), so re-running after a crash or a kill
continues where it stopped. A stage that fails is reported and the later stages still run on
whatever exists (the report says which sections were "not run").
"""

from __future__ import annotations

import time
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

from anomalygen import stages as registry
from anomalygen.errors import AnomalygenError
from anomalygen.runfolder import RunFolder

if TYPE_CHECKING:
    from anomalygen.config import Settings


def demo_config_path() -> Path:
    """The packaged TOML with the embedded offline defaults (used when ``run`` gets no --config)."""
    return Path(str(resources.files("anomalygen").joinpath("data/demo.toml")))


def run_pipeline(run: RunFolder, settings: Settings, *, force: bool = False, stages: list[str] | None = None) -> dict:
    """Run the stages in order; returns ``{"stages": {name: {...}}, "report": path or None, "wall_s": s}``."""
    from rich.console import Console

    err = Console(stderr=True)
    started = time.perf_counter()
    outcome: dict[str, Any] = {"run": str(run.root), "stages": {}, "report": None}
    for stage in registry.STAGES:
        name = stage.name
        if stages is not None and name not in stages:
            continue
        try:
            summary = stage.run(run, settings, force=force)
        except AnomalygenError as exc:
            outcome["stages"][name] = {"status": "failed", "reason": str(exc)}
            err.print(f"[red]{name}: failed — {exc}[/red]", highlight=False)
            continue
        outcome["stages"][name] = {
            "status": "done" if summary.ok or summary.done or summary.skipped else "failed",
            "done": summary.done,
            "skipped": summary.skipped,
            "failed": summary.failed,
            "wall_s": round(summary.wall_s, 3),
            "errors": dict(summary.errors),
        }
        err.print(summary.line(), highlight=False)
    index = run.report_dir / "index.html"
    if index.is_file():
        outcome["report"] = str(index)
        print(f"report: {index.resolve()}")
    outcome["wall_s"] = round(time.perf_counter() - started, 3)
    return outcome
