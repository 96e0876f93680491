"""Run one stage's items through an executor, with resume, per-item errors and a progress bar.

Every stage uses this one code path, locally (inline or a process pool) or on Ray, so resuming,
``--force`` and failure handling behave the same everywhere. Item functions must be module-level
(picklable) and write their own outputs atomically through :mod:`anomalygen.runfolder`.

Resume notices change: each item's fingerprint (its payload, the input files it reads and the
settings it reads, :func:`config_section`; :func:`anomalygen.runfolder.fingerprint`) is recorded
when the item succeeds, and an item counts as done only when its outputs are valid *and* the
recorded fingerprint is the current one. A re-planned task re-runs its skill; a rebuilt scene is
detected again; a setting no item of the stage reads redoes nothing.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
import traceback
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from anomalygen.errors import AnomalygenError, UserError
from anomalygen.runfolder import RunFolder, fingerprint, now_iso
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
    inputs: Callable[[str], Sequence[Path]] | None = None,
    config: Any = None,
) -> StageSummary:
    """Apply ``fn(item_id, payload, ctx)`` to every item not already done; never let one item kill the batch.

    ``inputs(item_id)``: the files the item reads (besides its payload); ``config``: the settings it
    depends on (:func:`config_section`). Both go into the item's fingerprint."""
    started = time.perf_counter()
    summary = StageSummary(stage)
    record = StageRecord(started=now_iso())
    ctx = StageContext(str(run.root), settings, stage)
    todo: list[tuple[str, Any, tuple[str, bool]]] = []
    for item_id, payload in items:
        fp = fingerprint(stage, payload, config, inputs(item_id) if inputs is not None else ())
        has_output = is_done is not None and is_done(item_id)
        if not force and has_output and run.read_fingerprint(stage, item_id) == fp:
            summary.skipped += 1
        else:
            todo.append((item_id, payload, (fp, has_output)))

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
            run.record_fingerprint(stage, item_id, None)  # also when the worker itself died

    summary.wall_s = time.perf_counter() - started
    record.finished = now_iso()
    record.wall_s = round(summary.wall_s, 3)
    record.done, record.skipped, record.failed = summary.done, summary.skipped, summary.failed
    run.record_stage(stage, record)
    return summary


def _call(fn: ItemFn, item_id: str, payload: Any, ctx: StageContext,
          fp: tuple[str, bool] | None = None) -> tuple[bool, Any]:
    """Run one item; expected failures become one line, unexpected ones keep their last frame.

    ``fp`` is (the item's fingerprint, whether valid outputs existed before it ran). Without earlier
    outputs the fingerprint is recorded first: any valid output found later was made from these
    inputs, so a kill right after the item writes never makes it run again. Over earlier outputs
    (stale, or ``--force``) the old record is dropped first and the new one written after success.
    A failed item keeps no record (it is redone next time)."""
    if fp is not None:
        ctx.run.record_fingerprint(ctx.stage, item_id, None if fp[1] else fp[0])
    try:
        value = fn(item_id, payload, ctx)
    except AnomalygenError as exc:
        outcome: tuple[bool, Any] = (False, str(exc))
    except Exception as exc:  # noqa: BLE001 - one bad item must not end the batch
        frame = traceback.extract_tb(exc.__traceback__)[-1] if exc.__traceback__ else None
        where = f" ({os.path.basename(frame.filename)}:{frame.lineno})" if frame else ""
        outcome = (False, f"{type(exc).__name__}: {exc}{where}")
    else:
        outcome = (True, value)
    if fp is not None and (fp[1] or not outcome[0]):
        ctx.run.record_fingerprint(ctx.stage, item_id, fp[0] if outcome[0] else None)
    return outcome


def _run_inline(todo, fn, ctx, advance) -> dict[str, tuple[bool, Any]]:
    outcomes = {}
    for item_id, payload, fp in todo:
        outcomes[item_id] = _call(fn, item_id, payload, ctx, fp)
        advance()
    return outcomes


def _run_pool(todo, fn, ctx, workers, advance) -> dict[str, tuple[bool, Any]]:
    # Workers die with this process (procs.child_pool): a killed run leaves none behind.
    from anomalygen.procs import child_pool

    outcomes = {}
    with child_pool(min(workers, len(todo))) as pool:
        futures = {pool.submit(_call, fn, item_id, payload, ctx, fp): item_id for item_id, payload, fp in todo}
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
        refs = {remote_call.remote(fn, item_id, payload, ctx, fp): item_id for item_id, payload, fp in todo}
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


def config_section(settings: Settings, section: str, *, exclude: Sequence[str] = (),
                   also: Mapping[str, Sequence[str]] | None = None, seed: bool = True, llm: bool = False) -> dict:
    """What a stage's items read of the settings, for their fingerprint: the stage's own section less
    the keys that change no item's output (``exclude``: e.g. how many seeds to run); ``also``: the keys
    it reads of other sections (``{"plan": ("max_fixes",)}``); ``seed``: the run's master seed; with
    ``llm``, the model that answers and how (``LLM_IDENTITY``, with any ``also["llm"]`` keys).

    Each stage declares its call in one function, ``reads(settings)``, next to its ``run_stage``, so
    resume redoes an item when a setting it reads changes, and only then."""
    out: dict[str, Any] = {section: getattr(settings, section).model_dump(mode="json", exclude=set(exclude))}
    if seed:
        out["seed"] = settings.seed
    others = {name: set(keys) for name, keys in (also or {}).items()}
    if llm:
        others["llm"] = others.get("llm", set()) | set(LLM_IDENTITY)
    for name, keys in others.items():
        out[name] = getattr(settings, name).model_dump(mode="json", include=keys)
    return out


LLM_IDENTITY = ("backend", "model", "base_url", "model_path", "temperature", "max_tokens", "n_ctx")


def check_only(only: Sequence[str] | None, known: Sequence[str], what: str = "task id") -> None:
    """An ``--only`` id the run does not have is a mistake: say so, with the closest id."""
    import difflib

    unknown = [i for i in dict.fromkeys(only or ()) if i not in set(known)]
    if not unknown:
        return
    parts = []
    for item in unknown:
        close = difflib.get_close_matches(item, list(known), n=1, cutoff=0.0)
        parts.append(f"'{item}'" + (f" (closest: '{close[0]}')" if close else ""))
    raise UserError(f"unknown {what}{'s' if len(unknown) > 1 else ''} in --only: {', '.join(parts)}; "
                    f"the run has {len(known)} {what}s")


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
