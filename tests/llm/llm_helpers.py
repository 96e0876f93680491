"""Small shared pieces of the LLM tests (a compact schema and valid/invalid reply texts)."""

from __future__ import annotations

import json

from anomalygen.schema import Scenario

VALID = {"hazard_object": "knife", "room": "kitchen", "placement": "counter_edge"}
VALID_TEXT = json.dumps(VALID)
USER = [{"role": "user", "content": "A knife lies on the edge of a kitchen counter."}]

__all__ = ["Scenario", "USER", "VALID", "VALID_TEXT"]
