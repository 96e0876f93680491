"""Suites and benchmark runs: what ``anomalygen suite build`` and ``anomalygen bench`` write.

Why typed files: a frozen suite must say how it was made (seed, engine, code version) and let anyone
check they hold the very scenes it was made with (a checksum of every scene's files); a bench run
must say which agent ran on which suite, what it did call by call, and the referee's table.
"""

from __future__ import annotations

from typing import Any

from pydantic import Field

from anomalygen.schema.base import Artefact, Strict
from anomalygen.schema.skills import SubTaskResult
from anomalygen.schema.verdicts import VerdictStatus


class SuiteScene(Strict):
    task_id: str
    sha256: str = Field(description="over the scene folder's files: their paths and bytes, in path order")
    files: int


class SuiteManifest(Artefact):
    """``suite.json`` in a suite's folder (a run folder with tasks.jsonl and scenes/)."""

    name: str
    version: int
    description: str = ""
    source: str = Field("", description="where the suite's tasks come from")
    engine: str
    seed: int
    package_version: str
    git_commit: str | None = None
    created: str
    settings: dict[str, Any] = Field(default_factory=dict, description="the brainstorm and build sections it was built with")
    tasks: int = Field(description="tasks brainstormed")
    scenes: list[SuiteScene] = Field(default_factory=list, description="the scenes that were built")
    not_built: list[str] = Field(default_factory=list, description="tasks whose scene failed to build")


class CallRecord(Strict):
    """One step of an agent's episode."""

    action: str = Field(description="what the agent sent, as text")
    call: str | None = Field(None, description="the call the env read, None when it read none")
    error: str | None = None
    executed: list[SubTaskResult] = Field(default_factory=list)
    control_steps: int = 0
    wall_s: float = 0.0


class EpisodeRecord(Artefact):
    """``skills/<task>/seed<k>/episode.json`` of a bench run: the agent's calls, in order."""

    task_id: str
    seed: int
    agent: str
    calls: list[CallRecord] = Field(default_factory=list)
    ended: str = Field(description="done, or the budget that truncated the episode")
    wall_s: float = 0.0


class BenchClassRow(Strict):
    hazards: int = 0
    detected: int | None = Field(None, description="named by the agent's reported detections; None: it reported none")
    runs: int = 0
    resolved: int = 0


class BenchRun(Strict):
    task_id: str
    seed: int
    status: VerdictStatus | None = Field(None, description="the referee's; None when the episode failed")
    calls: int = 0
    invalid_calls: int = 0
    new_hazards: list[str] = Field(default_factory=list)
    interventions_on_safe: list[str] = Field(default_factory=list)
    error: str | None = None


class BenchReport(Artefact):
    """``bench.json``: the referee's table of one agent on one suite, and every run's verdict."""

    agent: str
    suite: str = Field(description="name and version, or the folder of a run used as a suite")
    suite_dir: str
    seeds: int
    created: str
    package_version: str
    git_commit: str | None = None
    runs: int = 0
    runs_with_hazards: int = 0
    resolved: int = Field(0, description="runs on scenes with hazards: every hazard resolved and none made")
    hazard_free_runs: int = 0
    left_alone: int = Field(0, description="hazard-free runs that left the scene as it was (no_action_needed)")
    runs_with_new_hazards: int = 0
    runs_acting_on_safe: int = 0
    failed: int = Field(0, description="episodes that ended in an error (the agent raised): no verdict")
    by_class: dict[str, BenchClassRow] = Field(default_factory=dict, description="per hazard of the truth, by class")
    detection: dict[str, Any] | None = Field(None, description="the agent's reported detections scored against the truth")
    per_run: list[BenchRun] = Field(default_factory=list)
