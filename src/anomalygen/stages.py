"""The one list of pipeline stages, read by both ``cli.py`` and ``pipeline.py``.

Each entry names the stage, the package that owns it, the run-folder artefacts it reads and writes,
and how to call its ``run_stage``. Keeping that in one place means a new stage (or a renamed one)
is a one-line change, and the CLI and ``anomalygen run`` can never disagree on the order.
Stage modules are imported only when a stage runs, so ``--help`` stays instant.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from anomalygen.config import Settings
    from anomalygen.runfolder import RunFolder
    from anomalygen.runner import StageSummary


class Stage(Protocol):
    """What the pipeline needs to know about a stage."""

    name: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]

    def run(self, run: RunFolder, settings: Settings, *, force: bool = False,
            only: list[str] | None = None) -> StageSummary: ...

    def check_inputs(self, settings: Settings) -> None: ...


@dataclass(frozen=True)
class ModuleStage:
    """A stage whose logic is ``run_stage`` in ``module``.

    ``per_item`` says whether ``run_stage`` takes ``force``/``only`` (evaluate and report summarise
    the whole run, so they take neither; brainstorm makes the item list, so it takes no ``only``).
    """

    name: str
    module: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    takes_force: bool = True
    takes_only: bool = True

    def run(self, run: RunFolder, settings: Settings, *, force: bool = False,
            only: list[str] | None = None) -> StageSummary:
        fn = importlib.import_module(self.module).run_stage
        kwargs: dict = {}
        if self.takes_force:
            kwargs["force"] = force
        if self.takes_only:
            kwargs["only"] = only
        elif only:
            raise ValueError(f"stage {self.name} works on the whole run; it takes no --only")
        return fn(run, settings, **kwargs)

    def check_inputs(self, settings: Settings) -> None:
        """Read the user's own input files the stage will read (its module's ``check_inputs``, where it
        has one) and raise ``UserError`` on a bad one; writes nothing, so it runs before the run folder
        is created."""
        check = getattr(importlib.import_module(self.module), "check_inputs", None)
        if check is not None:
            check(settings)


STAGES: tuple[Stage, ...] = (
    ModuleStage("brainstorm", "anomalygen.brainstorm.stage", (), ("tasks.jsonl",), takes_only=False),
    ModuleStage("build", "anomalygen.scene.stage", ("tasks.jsonl",), ("scenes/<task_id>/",)),
    ModuleStage("detect", "anomalygen.detect.stage", ("tasks.jsonl", "scenes/"), ("detections.jsonl",)),
    ModuleStage("plan", "anomalygen.plan.stage", ("tasks.jsonl", "scenes/", "detections.jsonl"), ("plans/",)),
    ModuleStage("learn", "anomalygen.learn.stage", ("plans/", "scenes/"), ("skills/",)),
    # the referee, after the robot's items: detections judged, every run's final state judged
    ModuleStage("judge", "anomalygen.referee.stage", ("tasks.jsonl", "scenes/", "detections/", "skills/"),
                ("detections_summary.json", "skills/<task_id>/seed<k>/verdict.json")),
    ModuleStage("evaluate", "anomalygen.evaluate.stage", ("tasks.jsonl", "scenes/", "detections.jsonl", "skills/"),
                ("evaluation.json",), takes_force=False, takes_only=False),
    ModuleStage("report", "anomalygen.evaluate.report", ("evaluation.json",), ("report/",),
                takes_force=False, takes_only=False),
)


def stage(name: str) -> Stage:
    """The registered stage called ``name``."""
    for s in STAGES:
        if s.name == name:
            return s
    raise KeyError(f"no stage named {name!r}; stages: {', '.join(s.name for s in STAGES)}")
