"""Run one stage's items through an executor, with resume, per-item errors and a progress bar.

Every stage uses this one code path, locally (inline or a process pool) or on Ray, so resuming,
``--force`` and failure handling behave the same everywhere. Item functions must be module-level
(picklable) and write their own outputs atomically through :mod:`anomalygen.runfolder`.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
import traceback
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from multiprocessing import get_context
from typing import TYPE_CHECKING, Any

from anomalygen.errors import AnomalygenError
from anomalygen.runfolder import RunFolder, now_iso
from anomalygen.schema import StageRecord

if TYPE_CHECKING:
    from anomalygen.config import Settings

ItemFn = Callable[[str, Any, "StageContext"], Any]


@dataclass(frozen=True)
class StageContext:
    """What an item function needs besides its item: picklable, so it crosses process boundaries.

    The settings object itself travels (pickle keeps ``SecretStr`` values); a JSON dump would replace
    an API key with asterisks and workers would send those to the endpoint.
    """

    run_root: str
    settings: Settings
    stage: str

    @property
    def run(self) -> RunFolder:
        return RunFolder(self.run_root)


@dataclass
class StageSummary:
    stage: str
    done: int = 0
    skipped: int = 0
    failed: int = 0
    wall_s: float = 0.0
    errors: dict[str, str] = field(default_factory=dict)
    results: dict[str, Any] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.failed == 0

    def line(self) -> str:
        return (
            f"{self.stage}: {self.done} done, {self.skipped} skipped (already present), "
            f"{self.failed} failed in {self.wall_s:.1f}s"
        )


def run_items(
    run: RunFolder,
    stage: str,
    items: Sequence[tuple[str, Any]],
    fn: ItemFn,
    *,
    settings: Settings,
    is_done: Callable[[str], bool] | None = None,
    force: bool = False,
    workers: int | None = None,
    executor: str | None = None,
    description: str | None = None,
) -> StageSummary:
    """Apply ``fn(item_id, payload, ctx)`` to every item not already done; never let one item kill the batch."""
    started = time.perf_counter()
    summary = StageSummary(stage)
    record = StageRecord(started=now_iso())
    ctx = StageContext(str(run.root), settings, stage)
    todo: list[tuple[str, Any]] = []
    for item_id, payload in items:
        if not force and is_done is not None and is_done(item_id):
            summary.skipped += 1
        else:
            todo.append((item_id, payload))

    executor = executor or settings.executor
    workers = max(1, workers or settings.workers)
    with _progress(description or stage, len(todo), quiet=settings.quiet) as advance:
        if executor == "ray":
            outcomes = _run_ray(todo, fn, ctx, settings, advance)
        elif workers == 1 or len(todo) <= 1:
            outcomes = _run_inline(todo, fn, ctx, advance)
        else:
            outcomes = _run_pool(todo, fn, ctx, workers, advance)

    for item_id, (ok, value) in sorted(outcomes.items()):
        if ok:
            summary.done += 1
            summary.results[item_id] = value
            run.clear_error(stage, item_id)
        else:
            summary.failed += 1
            summary.errors[item_id] = value
            run.record_error(stage, item_id, value)

    summary.wall_s = time.perf_counter() - started
    record.finished = now_iso()
    record.wall_s = round(summary.wall_s, 3)
    record.done, record.skipped, record.failed = summary.done, summary.skipped, summary.failed
    run.record_stage(stage, record)
    return summary


def _call(fn: ItemFn, item_id: str, payload: Any, ctx: StageContext) -> tuple[bool, Any]:
    """Run one item; expected failures become one line, unexpected ones keep their last frame."""
    try:
        return True, fn(item_id, payload, ctx)
    except AnomalygenError as exc:
        return False, str(exc)
    except Exception as exc:  # noqa: BLE001 - one bad item must not end the batch
        frame = traceback.extract_tb(exc.__traceback__)[-1] if exc.__traceback__ else None
        where = f" ({os.path.basename(frame.filename)}:{frame.lineno})" if frame else ""
        return False, f"{type(exc).__name__}: {exc}{where}"


def _run_inline(todo, fn, ctx, advance) -> dict[str, tuple[bool, Any]]:
    outcomes = {}
    for item_id, payload in todo:
        outcomes[item_id] = _call(fn, item_id, payload, ctx)
        advance()
    return outcomes


def _run_pool(todo, fn, ctx, workers, advance) -> dict[str, tuple[bool, Any]]:
    # spawn, not fork: torch and MuJoCo's renderer do not survive a fork of a threaded parent.
    outcomes = {}
    with ProcessPoolExecutor(max_workers=min(workers, len(todo)), mp_context=get_context("spawn")) as pool:
        futures = {pool.submit(_call, fn, item_id, payload, ctx): item_id for item_id, payload in todo}
        for fut in as_completed(futures):
            item_id = futures[fut]
            try:
                outcomes[item_id] = fut.result()
            except Exception as exc:  # noqa: BLE001 - a worker died (OOM, segfault)
                outcomes[item_id] = (False, f"worker crashed: {type(exc).__name__}: {exc}")
            advance()
    return outcomes


def _run_ray(todo, fn, ctx, settings: Settings, advance) -> dict[str, tuple[bool, Any]]:
    try:
        import ray
    except ImportError as exc:  # pragma: no cover - depends on the optional extra
        from anomalygen.errors import UserError

        raise UserError("executor 'ray' needs Ray: pip install 'anomalygen[ray]'") from exc
    os.environ.setdefault("RAY_AUTH_MODE", "disabled")
    started_here = False
    if not ray.is_initialized():
        kwargs: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False}
        if settings.ray_address:
            kwargs["address"] = settings.ray_address
        else:
            kwargs["num_cpus"] = settings.workers
            # Like the spawn pool, workers of a local instance see the driver's import path, so item
            # functions defined outside the installed package (tests, user plugins) unpickle there too.
            kwargs["runtime_env"] = {"env_vars": {"PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}}
            kwargs["_temp_dir"] = tempfile.mkdtemp(prefix="ray-", dir=os.environ.get("ANOMALYGEN_RAY_TMP"))
        ray.init(**kwargs)
        started_here = True
    try:
        remote_call = ray.remote(_call)
        refs = {remote_call.remote(fn, item_id, payload, ctx): item_id for item_id, payload in todo}
        outcomes = {}
        pending = list(refs)
        while pending:
            ready, pending = ray.wait(pending, num_returns=1)
            for ref in ready:
                try:
                    outcomes[refs[ref]] = ray.get(ref)
                except Exception as exc:  # noqa: BLE001
                    outcomes[refs[ref]] = (False, f"ray task failed: {type(exc).__name__}: {exc}")
                advance()
        return outcomes
    finally:
        if started_here:
            ray.shutdown()


class _progress:
    """A rich progress bar on stderr, or nothing with ``--quiet``."""

    def __init__(self, description: str, total: int, *, quiet: bool):
        self.description, self.total, self.quiet = description, total, quiet
        self._progress = None

    def __enter__(self) -> Callable[[], None]:
        if self.quiet or self.total == 0:
            return lambda: None
        from rich.console import Console
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

        self._progress = Progress(
            TextColumn("[bold]{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeRemainingColumn(),
            console=Console(stderr=True),
            transient=False,
        )
        self._progress.start()
        task = self._progress.add_task(self.description, total=self.total)
        return lambda: self._progress.advance(task)

    def __exit__(self, *exc) -> None:
        if self._progress is not None:
            self._progress.stop()
