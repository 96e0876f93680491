"""Frozen suites: named, versioned sets of built scenes that any agent is measured on.

Why frozen: figures of two agents, or of one agent at two commits, compare only on the same scenes.
A suite is built by the pipeline's own stages (brainstorm, build) from fixed settings — the suite's
seed and engine and the stages' defaults; the user's config does not enter, so a build on another
machine gives the same scenes — and its manifest (``suite.json``, ``schema.SuiteManifest``) records the
seed, the engine, the code version and a checksum of every scene's files, which ``verify_suite``
checks. Any built run folder (``tasks.jsonl`` and ``scenes/``) serves as a suite too.

A suite named on the command line is looked for in :func:`suite_dir` (``$ANOMALYGEN_SUITES/<name>-v<version>``,
default ``~/.cache/anomalygen/suites/``); one not built there is an error that says how to build it:
``anomalygen suite build NAME`` (a few minutes for ``anomaly-111`` on two cores), rather than a
silent build in the middle of a benchmark.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from anomalygen.errors import UserError
from anomalygen.runfolder import RunFolder, now_iso, try_read_model, write_model
from anomalygen.scene_files import SCENE_SPEC, SUITE_MANIFEST
from anomalygen.schema import SuiteManifest, SuiteScene

SUITES_ENV = "ANOMALYGEN_SUITES"


@dataclass(frozen=True)
class SuiteDef:
    """How a named suite is made: brainstormed (``n`` tasks) or read from shipped plain lines."""

    name: str
    version: int
    description: str
    source: str
    seed: int = 0
    engine: str = "knowledge"
    n: int | None = None  # tasks the knowledge engine brainstorms
    lines: str | None = None  # a file of data/suites/ (JSON lines with "line"): the tasks as plain text
    build: dict = field(default_factory=dict)  # build settings beyond the defaults

    @property
    def label(self) -> str:
        return f"{self.name} v{self.version}"


SUITES: dict[str, SuiteDef] = {s.name: s for s in (
    SuiteDef("anomaly-111", 1, "the 111 knowledge-engine tasks of seed 0, built with the default judgement mix "
             "(near-misses, second hazards, hazard-free scenes)",
             "anomalygen brainstorm --engine knowledge --n 111 --seed 0; build --seed 0 (benchmarks/bench_loop.py)",
             n=111),
    SuiteDef("outside", 1, "hand-labelled hazard lines from public child-proofing checklists and IS-Bench that "
             "the offline reader composes and the builder builds",
             "data/suites/outside.jsonl, from benchmarks/data/outside_hazards.jsonl (sources in its README)",
             lines="outside.jsonl"),
)}


def suite_dir(name: str, version: int) -> Path:
    root = os.environ.get(SUITES_ENV)
    base = Path(root) if root else Path.home() / ".cache" / "anomalygen" / "suites"
    return base / f"{name}-v{version}"


def suite_def(name: str) -> SuiteDef:
    if name not in SUITES:
        raise UserError(f"no suite {name!r}; the suites: {', '.join(SUITES)} (or pass a built run folder)")
    return SUITES[name]


def suite_settings(defn: SuiteDef, *, workers: int | None = None, executor: str | None = None,
                   quiet: bool = False):
    """The settings a suite is built with: its own seed and engine, the stages' defaults otherwise."""
    from anomalygen.config import Settings

    brainstorm: dict = {"engine": defn.engine}
    if defn.n is not None:
        brainstorm["n"] = defn.n
    extra = {k: v for k, v in (("workers", workers), ("executor", executor)) if v is not None}
    return Settings(seed=defn.seed, quiet=quiet, brainstorm=brainstorm, build={"engine": defn.engine, **defn.build},
                    **extra)


def build_suite(defn: SuiteDef, out: Path, *, workers: int | None = None, executor: str | None = None,
                quiet: bool = False, force: bool = False) -> SuiteManifest:
    """Brainstorm and build the suite into ``out`` (resumable: built scenes are kept), then write its manifest."""
    from anomalygen.stages import stage

    out = Path(out)
    settings = suite_settings(defn, workers=workers, executor=executor, quiet=quiet)
    if defn.lines is not None:
        out.mkdir(parents=True, exist_ok=True)
        text = out / "lines.txt"
        rows = [json.loads(r) for r in resources.files("anomalygen").joinpath(f"data/suites/{defn.lines}")
                .read_text(encoding="utf-8").splitlines() if r.strip()]
        text.write_text("".join(r["line"] + "\n" for r in rows), encoding="utf-8")
        settings.brainstorm.tasks_text = str(text)
    run = RunFolder.create(out, settings=settings)
    stage("brainstorm").run(run, settings, force=force)
    stage("build").run(run, settings, force=force)
    manifest = describe(run, defn, settings)
    write_model(out / SUITE_MANIFEST, manifest)
    return manifest


def describe(run: RunFolder, defn: SuiteDef, settings) -> SuiteManifest:
    from anomalygen.version import __version__

    tasks = run.load_tasks()
    built = [t.id for t in tasks if (run.scene_dir(t.id) / SCENE_SPEC).is_file()]
    return SuiteManifest(
        name=defn.name, version=defn.version, description=defn.description, source=defn.source, engine=defn.engine,
        seed=defn.seed, package_version=__version__, git_commit=run.load_manifest().git_commit, created=now_iso(),
        settings={k: settings.model_dump(mode="json")[k] for k in ("brainstorm", "build")}, tasks=len(tasks),
        scenes=[scene_checksum(run.scene_dir(t)) for t in built], not_built=[t.id for t in tasks if t.id not in built])


def scene_checksum(scene: Path) -> SuiteScene:
    """sha256 over every file of the scene folder: its relative path and its bytes, in path order."""
    h = hashlib.sha256()
    files = sorted(p for p in scene.rglob("*") if p.is_file())
    for p in files:
        h.update(p.relative_to(scene).as_posix().encode() + b"\0")
        h.update(hashlib.sha256(p.read_bytes()).digest())
    return SuiteScene(task_id=scene.name, sha256=h.hexdigest(), files=len(files))


@dataclass(frozen=True)
class Suite:
    """A suite to run on: its folder, its manifest (None for a plain run folder) and its built scenes."""

    root: Path
    manifest: SuiteManifest | None
    task_ids: list[str]

    @property
    def label(self) -> str:
        return f"{self.manifest.name} v{self.manifest.version}" if self.manifest else str(self.root)


def open_suite(name_or_dir: str | Path) -> Suite:
    """A suite by name (built in :func:`suite_dir`) or a folder (a suite's, or any built run's)."""
    path = Path(name_or_dir)
    if not path.is_dir():
        if str(name_or_dir) not in SUITES:
            raise UserError(f"{name_or_dir} is neither a folder nor a suite ({', '.join(SUITES)})")
        defn = SUITES[str(name_or_dir)]
        path = suite_dir(defn.name, defn.version)
        if not (path / SUITE_MANIFEST).is_file():
            raise UserError(f"the suite {defn.label} is not built: run 'anomalygen suite build {defn.name}' "
                            f"(it builds into {path}; set ${SUITES_ENV} for another place), or pass --suite DIR")
    manifest = try_read_model(path / SUITE_MANIFEST, SuiteManifest)
    run = RunFolder(path)
    if manifest is not None:
        ids = [s.task_id for s in manifest.scenes]
    else:
        ids = [t.id for t in run.load_tasks() if (run.scene_dir(t.id) / SCENE_SPEC).is_file()]
    if not ids:
        raise UserError(f"{path} holds no built scene (build it with 'anomalygen build --run {path}')")
    return Suite(path, manifest, ids)


def verify_suite(suite: Suite) -> list[str]:
    """What differs from the manifest's checksums (nothing: the suite's scenes are the ones it was built with)."""
    if suite.manifest is None:
        return [f"{suite.root} has no {SUITE_MANIFEST}: nothing to verify against"]
    out = []
    run = RunFolder(suite.root)
    for s in suite.manifest.scenes:
        scene = run.scene_dir(s.task_id)
        if not scene.is_dir():
            out.append(f"{s.task_id}: missing")
        elif (now := scene_checksum(scene)).sha256 != s.sha256:
            out.append(f"{s.task_id}: changed ({now.files} files, {s.files} when built)")
    return out
