"""Small shared pieces of the LLM tests (a compact schema and valid/invalid reply texts)."""

from __future__ import annotations

import json

from anomalygen.schema import Scenario

VALID = {"hazard_object": "knife", "room": "kitchen", "placement": "counter_edge"}
VALID_TEXT = json.dumps(VALID)
USER = [{"role": "user", "content": "A knife lies on the edge of a kitchen counter."}]


def complete_in_child(client, start: int, n: int) -> list[str]:
    """Run in a spawn worker (kept in this light module so the child imports little)."""
    messages = [[{"role": "user", "content": f"child {i}"}] for i in range(start, start + n)]
    return [client.complete(m, schema=Scenario).room for m in messages]


__all__ = ["Scenario", "USER", "VALID", "VALID_TEXT", "complete_in_child"]
