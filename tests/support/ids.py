"""Checks that task ids and what the robot perceives carry none of a task's own words."""

from __future__ import annotations

import re
from typing import get_args

from anomalygen.schema import Relation, TaskProposal

ID_PATTERN = re.compile(r"t\d{4}-[0-9a-f]{8}")
MIN_WORD = 4  # letters: shorter words ("on", "the", "a") say nothing about a task
# longer function words say nothing either; an observation's own prose may hold them ("from the edge")
FUNCTION_WORDS = frozenset({"from", "with", "into", "onto", "over", "away", "that", "this", "there", "their",
                            "them", "they", "have", "been", "were", "what", "when", "where", "which", "some",
                            "than", "then", "also", "each", "every"})


def words(text: str) -> set[str]:
    """Lower-case alphabetic tokens of at least ``MIN_WORD`` letters (underscores split words)."""
    return {w for w in re.split(r"[^a-z]+", text.lower()) if len(w) >= MIN_WORD and w not in FUNCTION_WORDS}


def task_text(task: TaskProposal) -> str:
    return " ".join([task.name, task.description, task.explanation, task.solution or "", task.success_condition or ""])


def assert_ids_carry_no_task_words(tasks: list[TaskProposal]) -> None:
    ids = [t.id for t in tasks]
    assert len(set(ids)) == len(ids), "task ids must be unique"
    for t in tasks:
        assert ID_PATTERN.fullmatch(t.id), t.id
        assert not words(t.id) & words(task_text(t)), t.id


def keys_and_values(obj, keys: set[str], values: list[str]) -> None:
    if isinstance(obj, dict):
        for k, v in obj.items():
            keys.add(str(k))
            keys_and_values(v, keys, values)
    elif isinstance(obj, list):
        for v in obj:
            keys_and_values(v, keys, values)
    elif isinstance(obj, str):
        values.append(obj)


def assert_no_task_words(task, dumps: dict[str, object]) -> None:
    """No distinctive word of the task (one that is not an object, room, property, part, relation,
    support or field name, all of which the robot may see) appears in any value; nor its id, class
    or name."""
    from anomalygen.knowledge import load_kb
    from anomalygen.knowledge.models import PROPERTIES, ROOMS, SUPPORT_HEIGHTS

    kb = load_kb()
    keys: set[str] = set()
    found: dict[str, list[str]] = {}
    for what, dump in dumps.items():
        found[what] = []
        keys_and_values(dump, keys, found[what])
    visible = [*kb.objects, *ROOMS, *PROPERTIES, *keys, *get_args(Relation.model_fields["predicate"].annotation),
               *(p.label for o in kb.objects.values() for p in o.parts), *SUPPORT_HEIGHTS, "support"]
    seen_anyway = set().union(*(words(n) for n in visible))
    distinctive = words(task_text(task)) - seen_anyway
    assert len(distinctive) >= 5, distinctive  # the check has teeth
    for what, values in found.items():
        text = " ".join(values).lower()
        leaked = distinctive & words(text)
        assert not leaked, (what, leaked)
        for secret in (task.id, task.hazard_class, task.name.lower()):
            assert secret.lower() not in text, (what, secret)
