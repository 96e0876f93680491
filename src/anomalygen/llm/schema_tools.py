"""JSON schemas handed to models, derived from the pydantic classes that validate their replies.

Two variants: ``response_schema`` is the faithful schema (OpenAI ``json_schema`` / Anthropic tool
input), ``bounded_schema`` adds ``maxLength``/``maxItems`` caps and drops optional fields so a
grammar-constrained local model cannot ramble for minutes. Validation always uses the real model,
so the caps only shape generation, never what is accepted.
"""

from __future__ import annotations

import copy
import functools
import json
from typing import Any

from pydantic import BaseModel


def response_schema(schema: type[BaseModel]) -> dict[str, Any]:
    """The class's JSON schema (a fresh copy: callers may mutate it)."""
    return copy.deepcopy(_cached_schema(schema))


@functools.lru_cache(maxsize=256)
def _cached_schema(schema: type[BaseModel]) -> dict[str, Any]:
    return schema.model_json_schema()


@functools.lru_cache(maxsize=256)
def schema_fingerprint(schema: type[BaseModel] | None) -> str | None:
    """Canonical JSON of the schema, part of the cache key (a changed class invalidates old replies)."""
    if schema is None:
        return None
    return json.dumps(_cached_schema(schema), sort_keys=True, separators=(",", ":"))


def inline_refs(node: Any, defs: dict[str, Any], depth: int = 0) -> Any:
    """Replace ``$ref`` pointers into ``$defs`` by copies (bounded depth; our models are not recursive)."""
    if depth > 32:
        return {}
    if isinstance(node, dict):
        ref = node.get("$ref")
        if isinstance(ref, str) and ref.startswith("#/$defs/"):
            target = copy.deepcopy(defs.get(ref.split("/")[-1], {}))
            extra = {k: v for k, v in node.items() if k != "$ref"}
            target.update(extra)
            return inline_refs(target, defs, depth + 1)
        return {k: inline_refs(v, defs, depth + 1) for k, v in node.items() if k != "$defs"}
    if isinstance(node, list):
        return [inline_refs(v, defs, depth + 1) for v in node]
    return node


def bounded_schema(
    schema: type[BaseModel], *, max_string: int = 60, max_items: int = 2, required_only: bool = True
) -> dict[str, Any]:
    """A self-contained schema with generation caps, for grammar-constrained local decoding."""
    raw = response_schema(schema)
    tree = inline_refs(raw, raw.get("$defs", {}))
    return _cap(tree, max_string=max_string, max_items=max_items, required_only=required_only)


def _cap(node: Any, *, max_string: int, max_items: int, required_only: bool) -> Any:
    if isinstance(node, list):
        return [
            _cap(v, max_string=max_string, max_items=max_items, required_only=required_only) for v in node
        ]
    if not isinstance(node, dict):
        return node
    out = {k: v for k, v in node.items() if k not in ("title", "description", "default", "examples")}
    kw = {"max_string": max_string, "max_items": max_items, "required_only": required_only}
    if out.get("type") == "object" and isinstance(out.get("properties"), dict):
        required = set(out.get("required", []))
        props = out["properties"]
        if required_only and required:
            props = {k: v for k, v in props.items() if k in required}
            out["required"] = [k for k in out.get("required", []) if k in props]
        out["properties"] = {k: _cap(v, **kw) for k, v in props.items()}
        out.setdefault("additionalProperties", False)
    elif out.get("type") == "object" and isinstance(out.get("additionalProperties"), dict):
        out["additionalProperties"] = _cap(out["additionalProperties"], **kw)
        out.setdefault("maxProperties", max_items)
    for key in ("anyOf", "oneOf", "allOf", "prefixItems"):
        if key in out:
            out[key] = _cap(out[key], **kw)
    if "items" in out:
        out["items"] = _cap(out["items"], **kw)
    if out.get("type") == "string" and not ({"enum", "const", "pattern", "format"} & out.keys()):
        out["maxLength"] = min(int(out.get("maxLength", max_string)), max_string)
    if out.get("type") == "array" and "prefixItems" not in out:
        out["maxItems"] = min(
            int(out.get("maxItems", max_items)), max(max_items, int(out.get("minItems", 0)))
        )
    return out


#: Tokens a reply spends per field kind: a free-text string (a sentence or a few), a short name, a
#: list (a few names), plus the JSON punctuation and the field name itself.
TOKENS_PER_TEXT_FIELD = 96
TOKENS_PER_NAME_FIELD = 16
TOKENS_PER_LIST_FIELD = 48
TEXT_FIELD_HINTS = ("sentence", "why", "situation", "explanation", "description", "how", "words")


def reply_token_budget(schema: type[BaseModel], *, floor: int = 128, cap: int | None = None) -> int:
    """``max_tokens`` for one reply of ``schema``, sized from its fields rather than one global value.

    Why: a fixed budget either truncates a long object (the reply is then invalid JSON) or, when
    several objects are asked for at once, hides how many were cut off. Free-text fields (named like
    description or documented as sentences) get a paragraph's worth, names a few words, lists a few
    names; 25 % on top covers JSON syntax and the field names. ``cap`` (the configured
    ``llm.max_tokens``) stays an upper bound the user can set.
    """
    total = 0
    for name, info in schema.model_fields.items():
        doc = f"{name} {info.description or ''}".lower()
        annotation = str(info.annotation)
        if "list" in annotation:
            total += TOKENS_PER_LIST_FIELD
        elif any(h in doc for h in TEXT_FIELD_HINTS) or name in ("solution", "success_condition", "explanation"):
            total += TOKENS_PER_TEXT_FIELD
        else:
            total += TOKENS_PER_NAME_FIELD
    budget = max(floor, int(total * 1.25))
    return budget if cap is None else min(budget, int(cap))
