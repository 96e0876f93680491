"""Add a client's token/cache/cost counts to the run manifest (``manifest.llm_usage``)."""

from __future__ import annotations

import contextlib
from pathlib import Path

from anomalygen.schema import LLMUsage


@contextlib.contextmanager
def _process_lock(path: Path):
    """An advisory file lock, so record_usage calls from several worker processes do not lose counts."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - non-POSIX
        yield
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "a+") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def record_usage(run, usage: LLMUsage) -> LLMUsage:
    """Accumulate ``usage`` into ``run``'s manifest; returns the new run total.

    Safe between threads (the run folder's lock) and between processes that all use this function
    (a file lock next to the manifest).
    """
    with _process_lock(Path(run.root) / ".llm_usage.lock"), run.update_manifest() as manifest:
        manifest.llm_usage.add(usage)
        total = manifest.llm_usage.model_copy()
    return total
