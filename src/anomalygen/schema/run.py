"""Run bookkeeping: the run manifest (stages, LLM usage) and a failed item's record."""

from __future__ import annotations

from typing import Any

from pydantic import Field

from anomalygen.schema.base import Artefact, Strict


class StageRecord(Strict):
    started: str | None = None
    finished: str | None = None
    wall_s: float = 0.0
    done: int = 0
    skipped: int = 0
    failed: int = 0


class LLMUsage(Strict):
    requests: int = 0
    prompt_tokens: int = 0
    completion_tokens: int = 0
    cache_hits: int = 0
    cache_misses: int = 0
    retries: int = 0
    truncated: int = Field(0, description="replies that used the whole max_tokens budget (likely cut off)")
    cost_usd: float | None = None

    def add(self, other: LLMUsage) -> None:
        for field in ("requests", "prompt_tokens", "completion_tokens", "cache_hits", "cache_misses", "retries", "truncated"):
            setattr(self, field, getattr(self, field) + getattr(other, field))
        if other.cost_usd is not None:
            self.cost_usd = (self.cost_usd or 0.0) + other.cost_usd


class RunManifest(Artefact):
    name: str
    created: str
    package_version: str
    git_commit: str | None = None
    seed: int = 0
    config: dict[str, Any] = Field(default_factory=dict, description="effective config, secrets masked")
    llm_backend: str | None = None
    llm_model: str | None = None
    stages: dict[str, StageRecord] = Field(default_factory=dict)
    llm_usage: LLMUsage = Field(default_factory=LLMUsage)


class ItemError(Artefact):
    """A per-item failure, written in place of the item's output so a batch never dies of one item."""

    item_id: str
    stage: str
    error: str
