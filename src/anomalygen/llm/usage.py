"""Add a client's token/cache/cost counts to the run manifest (``manifest.llm_usage``)."""

from __future__ import annotations

from anomalygen.schema import LLMUsage


def record_usage(run, usage: LLMUsage) -> LLMUsage:
    """Accumulate ``usage`` into ``run``'s manifest under its lock; returns the new run total."""
    with run.update_manifest() as manifest:
        manifest.llm_usage.add(usage)
        total = manifest.llm_usage.model_copy()
    return total
