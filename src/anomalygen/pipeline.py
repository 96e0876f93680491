"""``anomalygen run``: every stage in order, each through its own ``run_stage``, resumable per item.

The pipeline owns no stage logic. It calls brainstorm → build → detect → plan → learn → evaluate →
report; each stage skips items whose outputs already exist (``anomalygen.runner``), so re-running
after a crash or a kill continues where it stopped. A stage whose module has not been installed is
reported as skipped, and a stage that fails is reported and the later stages still run on whatever
exists (the report says which sections were "not run").
"""

from __future__ import annotations

import importlib
import inspect
import time
from importlib import resources
from pathlib import Path
from typing import Any

from anomalygen.errors import AnomalygenError
from anomalygen.runfolder import RunFolder

STAGES: list[tuple[str, str]] = [
    ("brainstorm", "anomalygen.brainstorm.stage"),
    ("build", "anomalygen.scene.stage"),
    ("detect", "anomalygen.detect.stage"),
    ("plan", "anomalygen.plan.stage"),
    ("learn", "anomalygen.learn.stage"),
    ("evaluate", "anomalygen.evaluate.stage"),
    ("report", "anomalygen.evaluate.report"),
]


def demo_config_path() -> Path:
    """The packaged TOML with the embedded offline defaults (used when ``run`` gets no --config)."""
    return Path(str(resources.files("anomalygen").joinpath("data/demo.toml")))


def _entry_point(module: str):
    """The stage's ``run_stage``, or None when its module is not there yet."""
    try:
        mod = importlib.import_module(module)
    except ModuleNotFoundError as exc:
        if exc.name and (module == exc.name or module.startswith(exc.name + ".")):
            return None
        raise
    return getattr(mod, "run_stage", None)


def _call(fn, run: RunFolder, settings, force: bool):
    """Pass ``force``/``only`` only to stages whose signature takes them (evaluate/report do not)."""
    params = inspect.signature(fn).parameters
    kwargs: dict[str, Any] = {}
    if "force" in params:
        kwargs["force"] = force
    if "only" in params:
        kwargs["only"] = None
    return fn(run, settings, **kwargs)


def run_pipeline(run: RunFolder, settings, *, force: bool = False, stages: list[str] | None = None) -> dict:
    """Run the stages in order; returns ``{"stages": {name: {...}}, "report": path or None, "wall_s": s}``."""
    from rich.console import Console

    err = Console(stderr=True)
    started = time.perf_counter()
    outcome: dict[str, Any] = {"run": str(run.root), "stages": {}, "report": None}
    for name, module in STAGES:
        if stages is not None and name not in stages:
            continue
        fn = _entry_point(module)
        if fn is None:
            outcome["stages"][name] = {"status": "skipped", "reason": f"stage not implemented yet ({module})"}
            err.print(f"[yellow]{name}: skipped — not implemented yet ({module})[/yellow]", highlight=False)
            continue
        try:
            summary = _call(fn, run, settings, force)
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
