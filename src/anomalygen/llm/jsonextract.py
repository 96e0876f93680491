"""Find the JSON object in an LLM reply.

Models wrap JSON in code fences, chat around it, or stop half-way. We never trust position in the
text (the reference code parsed by line number); instead we scan for the first balanced ``{...}``
(or ``[...]``) that parses, preferring fenced blocks. Failure is a ``JSONExtractError`` whose message
is short enough to send back to the model in a repair request.
"""

from __future__ import annotations

import json
import re
from typing import Any

_FENCE = re.compile(r"```(?:json|JSON)?\s*\n?(.*?)```", re.DOTALL)
MAX_SCAN_CHARS = 400_000  # bound the work on absurd replies
MAX_CANDIDATES = 50


class JSONExtractError(ValueError):
    """The reply holds no parseable JSON value."""


def extract_json(text: str) -> Any:
    """The first JSON object (or array) found in ``text``; raises ``JSONExtractError``."""
    if not isinstance(text, str) or not text.strip():
        raise JSONExtractError("the reply was empty; reply with a single JSON object")
    if len(text) > MAX_SCAN_CHARS:
        raise JSONExtractError(
            f"the reply is too long ({len(text)} characters); reply with a compact JSON object"
        )
    stripped = text.strip()
    try:
        return json.loads(stripped)
    except (json.JSONDecodeError, RecursionError):
        pass
    for block in _FENCE.findall(text):
        try:
            return json.loads(block.strip())
        except (json.JSONDecodeError, RecursionError):
            continue
    decoder = json.JSONDecoder()
    tried = 0
    for match in re.finditer(r"[{\[]", text):
        tried += 1
        if tried > MAX_CANDIDATES:
            break
        try:
            value, _ = decoder.raw_decode(text, match.start())
        except (json.JSONDecodeError, RecursionError):
            continue
        if isinstance(value, dict) or (isinstance(value, list) and value):
            return value
    if "{" in text and text.count("{") > text.count("}"):
        raise JSONExtractError(
            "the JSON object is truncated (unbalanced braces); reply with the complete object"
        )
    raise JSONExtractError(
        "no JSON object found in the reply; reply with a single JSON object and nothing else"
    )
