"""The run folder: every artefact is a file, written atomically, so any stage can resume or re-run.

Layout (see docs/run-folder.md)::

    runs/<name>/manifest.json
    runs/<name>/tasks.jsonl
    runs/<name>/scenes/<task_id>/{scene.json, scene.xml, scene_graph.json, render_*.png, assets/}
    runs/<name>/detections/<task_id>.json   -> collated into detections.jsonl
    runs/<name>/plans/<task_id>.json
    runs/<name>/skills/<task_id>/seed<k>/{result.json, video.mp4}
    runs/<name>/report/{index.html, report.json, summary.md}
    runs/<name>/errors/<stage>/<item_id>.json   (per-item failures)
    runs/<name>/fingerprints/<stage>/<item_id>.sha256   (what each finished item was made from)
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import hashlib
import json
import os
import subprocess
import tempfile
import threading
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, TypeVar

from pydantic import BaseModel, ValidationError

from anomalygen.errors import UserError
from anomalygen.schema import ItemError, RunManifest, StageRecord, format_validation_error
from anomalygen.textfile import read_lines

if TYPE_CHECKING:
    from anomalygen.config import Settings

M = TypeVar("M", bound=BaseModel)

_MANIFEST_LOCK = threading.Lock()


def now_iso() -> str:
    return _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds")


# --------------------------------------------------------------------------- atomic file I/O


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write to a temp file in the same folder, fsync, then rename: readers never see half a file."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def atomic_write_text(path: Path, text: str) -> None:
    atomic_write_bytes(path, text.encode("utf-8"))


def write_model(path: Path, model: BaseModel) -> None:
    atomic_write_text(path, model.model_dump_json(indent=2) + "\n")


def read_model(path: Path, cls: type[M]) -> M:
    """Read and validate one JSON artefact; raises UserError with a one-line reason."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError as exc:
        raise UserError(f"missing file: {path}") from exc
    except (OSError, UnicodeDecodeError) as exc:
        raise UserError(f"cannot read {path}: {exc}") from exc
    try:
        return cls.model_validate_json(text)
    except ValidationError as exc:
        raise UserError(f"{path}: invalid {cls.__name__}: {format_validation_error(exc)}") from exc


def try_read_model(path: Path, cls: type[M]) -> M | None:
    """The model if the file exists and validates, else None (the resume test)."""
    try:
        return read_model(path, cls)
    except UserError:
        return None


def write_jsonl(path: Path, models: Iterable[BaseModel]) -> None:
    atomic_write_text(path, "".join(m.model_dump_json() + "\n" for m in models))


def read_jsonl(path: Path, cls: type[M], *, strict: bool = True, what: str = "JSONL file") -> list[M]:
    """Read a JSONL file of artefacts. With ``strict`` every bad line is reported, by line number."""
    return [item for _, item in read_jsonl_numbered(path, cls, strict=strict, what=what)]


def read_jsonl_numbered(path: Path, cls: type[M], *, strict: bool = True,
                        what: str = "JSONL file") -> list[tuple[int, M]]:
    """``read_jsonl`` with each artefact's line number. The file is read as text by
    ``anomalygen.textfile`` (``what`` names it there): a folder, a binary file or text that is not
    UTF-8 is one ``UserError`` line, strict or not. One bad line is reported on one line."""
    path = Path(path)
    items: list[tuple[int, M]] = []
    problems: list[str] = []
    for lineno, line in enumerate(read_lines(path, what=what), start=1):
        if not line.strip():
            continue
        try:
            items.append((lineno, cls.model_validate_json(line)))
        except ValidationError as exc:
            problems.append(f"line {lineno}: {format_validation_error(exc, limit=3)}")
    if problems and strict:
        if len(problems) == 1:
            line, reason = problems[0].split(": ", 1)
            raise UserError(f"{path}, {line}: not a valid {cls.__name__}: {reason}; each line holds one "
                            f"{cls.__name__} as JSON (see 'anomalygen schema {cls.__name__}')")
        shown = "\n  ".join(problems[:20])
        raise UserError(f"{path}: {len(problems)} invalid {cls.__name__} line(s):\n  {shown}")
    return items


def fingerprint(*parts) -> str:
    """sha256 over what an item is made from: JSON-able values (payloads, config sections) and, for
    each path in a list or tuple, its name and bytes ("missing" when absent). A model counts as its
    JSON. Key order never matters; a changed byte in any input does."""
    h = hashlib.sha256()

    def add(part) -> None:
        if isinstance(part, (list, tuple)) and all(isinstance(x, Path) for x in part):
            for path in part:
                h.update(f"file {path.name}\0".encode())
                h.update(path.read_bytes() if path.is_file() else b"missing")
                h.update(b"\0")
            return
        if isinstance(part, BaseModel):
            part = part.model_dump(mode="json")
        h.update(json.dumps(part, sort_keys=True, default=str).encode())
        h.update(b"\0")

    for part in parts:
        add(part)
    return h.hexdigest()


# --------------------------------------------------------------------------- run folder


class RunFolder:
    """A run folder on disk. All paths of the layout are derived here, nowhere else."""

    def __init__(self, root: str | Path):
        self.root = Path(root)
        if (self.root / "knowledge").is_dir():  # hazard classes an LLM proposed for this run
            from anomalygen.knowledge.base import add_run_classes

            add_run_classes(self.root)

    # -- opening
    @classmethod
    def create(cls, root: str | Path, *, settings: Settings | None = None) -> RunFolder:
        run = cls(root)
        run._refuse_a_file()
        try:
            run.root.mkdir(parents=True, exist_ok=True)
        except OSError as exc:  # a file on the way, no permission, a read-only disk
            raise UserError(f"{run.root}: cannot create the run folder: {(exc.strerror or str(exc)).lower()}") from None
        run.sweep_temp_files()
        if not run.manifest_path.exists():
            run.save_manifest(run._new_manifest(settings))
        elif settings is not None:
            with run.update_manifest() as m:
                m.config = settings.masked_dump()
                m.seed = settings.seed
                m.llm_backend = settings.llm.backend
                m.llm_model = settings.llm.model or settings.llm.model_path
        return run

    @classmethod
    def open(cls, root: str | Path) -> RunFolder:
        run = cls(root)
        run._refuse_a_file()
        if not run.root.is_dir():
            raise UserError(f"run folder not found: {run.root} (create one with 'anomalygen brainstorm --out {run.root}')")
        run.sweep_temp_files()
        return run

    def _refuse_a_file(self) -> None:
        if self.root.exists() and not self.root.is_dir():
            raise UserError(f"{self.root}: a file, not a run folder; give --run a folder's path (a new one is created)")

    def sweep_temp_files(self) -> int:
        """Delete temp files left by a process killed mid-write; they were never visible as outputs."""
        removed = 0
        for tmp in self.root.rglob(".*.tmp"):
            with contextlib.suppress(OSError):
                tmp.unlink()
                removed += 1
        return removed

    def _new_manifest(self, settings: Settings) -> RunManifest:
        from anomalygen.version import __version__

        return RunManifest(
            name=self.root.name,
            created=now_iso(),
            package_version=__version__,
            git_commit=_git_commit(),
            seed=settings.seed if settings else 0,
            config=settings.masked_dump() if settings else {},
            llm_backend=settings.llm.backend if settings else None,
            llm_model=(settings.llm.model or settings.llm.model_path) if settings else None,
        )

    # -- layout
    @property
    def manifest_path(self) -> Path:
        return self.root / "manifest.json"

    @property
    def tasks_path(self) -> Path:
        return self.root / "tasks.jsonl"

    @property
    def scenes_dir(self) -> Path:
        return self.root / "scenes"

    def scene_dir(self, task_id: str) -> Path:
        return self.scenes_dir / task_id

    @property
    def detections_dir(self) -> Path:
        return self.root / "detections"

    @property
    def detections_path(self) -> Path:
        return self.root / "detections.jsonl"

    @property
    def plans_dir(self) -> Path:
        return self.root / "plans"

    def plan_path(self, task_id: str) -> Path:
        return self.plans_dir / f"{task_id}.json"

    @property
    def skills_dir(self) -> Path:
        return self.root / "skills"

    def skill_dir(self, task_id: str, seed: int) -> Path:
        return self.skills_dir / task_id / f"seed{seed}"

    @property
    def report_dir(self) -> Path:
        return self.root / "report"

    def error_path(self, stage: str, item_id: str) -> Path:
        return self.root / "errors" / stage / f"{item_id}.json"

    def fingerprint_path(self, stage: str, item_id: str) -> Path:
        return self.root / "fingerprints" / stage / f"{item_id}.sha256"

    # -- tasks
    def load_tasks(self):
        from anomalygen.schema import TaskProposal

        if not self.tasks_path.is_file():
            raise UserError(f"{self.tasks_path} not found: run 'anomalygen brainstorm --out {self.root}' first")
        return read_jsonl(self.tasks_path, TaskProposal)

    # -- per-item errors
    def record_error(self, stage: str, item_id: str, error: str) -> None:
        write_model(self.error_path(stage, item_id), ItemError(item_id=item_id, stage=stage, error=error))

    def clear_error(self, stage: str, item_id: str) -> None:
        with contextlib.suppress(FileNotFoundError):
            self.error_path(stage, item_id).unlink()

    def errors(self, stage: str) -> list[ItemError]:
        folder = self.root / "errors" / stage
        if not folder.is_dir():
            return []
        return [e for p in sorted(folder.glob("*.json")) if (e := try_read_model(p, ItemError)) is not None]

    # -- fingerprints: what each finished item was made from (see anomalygen.runner)
    def read_fingerprint(self, stage: str, item_id: str) -> str | None:
        try:
            return self.fingerprint_path(stage, item_id).read_text(encoding="utf-8").strip() or None
        except (FileNotFoundError, OSError, UnicodeDecodeError):
            return None

    def record_fingerprint(self, stage: str, item_id: str, value: str | None) -> None:
        """Record ``value`` for a finished item; None forgets it (the item is redone next time)."""
        if value is None:
            with contextlib.suppress(FileNotFoundError):
                self.fingerprint_path(stage, item_id).unlink()
        else:
            atomic_write_text(self.fingerprint_path(stage, item_id), value + "\n")

    # -- manifest
    def load_manifest(self) -> RunManifest:
        if not self.manifest_path.exists():
            return self._new_manifest(None)
        return read_model(self.manifest_path, RunManifest)

    def save_manifest(self, manifest: RunManifest) -> None:
        write_model(self.manifest_path, manifest)

    @contextlib.contextmanager
    def update_manifest(self) -> Iterator[RunManifest]:
        """Read-modify-write the manifest under a thread lock and a file lock (workers are processes)."""
        import fcntl

        self.root.mkdir(parents=True, exist_ok=True)
        with _MANIFEST_LOCK, open(self.root / ".manifest.lock", "a+") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            try:
                manifest = self.load_manifest()
                yield manifest
                self.save_manifest(manifest)
            finally:
                fcntl.flock(lock, fcntl.LOCK_UN)

    def record_stage(self, stage: str, record: StageRecord) -> None:
        with self.update_manifest() as m:
            m.stages[stage] = record


def _git_commit() -> str | None:
    try:
        out = subprocess.run(
            ["git", "rev-parse", "HEAD"],
            capture_output=True,
            text=True,
            timeout=5,
            cwd=Path(__file__).resolve().parent,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None if out.returncode == 0 else None
