"""Checks that task ids and what the robot perceives carry none of a task's own words."""

from __future__ import annotations

import re

from anomalygen.schema import TaskProposal

ID_PATTERN = re.compile(r"t\d{4}-[0-9a-f]{8}")
MIN_WORD = 4  # letters: shorter words ("on", "the", "a") say nothing about a task


def words(text: str) -> set[str]:
    """Lower-case alphabetic tokens of at least ``MIN_WORD`` letters (underscores split words)."""
    return {w for w in re.split(r"[^a-z]+", text.lower()) if len(w) >= MIN_WORD}


def task_text(task: TaskProposal) -> str:
    return " ".join([task.name, task.description, task.explanation, task.solution or "", task.success_condition or ""])


def assert_ids_carry_no_task_words(tasks: list[TaskProposal]) -> None:
    ids = [t.id for t in tasks]
    assert len(set(ids)) == len(ids), "task ids must be unique"
    for t in tasks:
        assert ID_PATTERN.fullmatch(t.id), t.id
        assert not words(t.id) & words(task_text(t)), t.id
