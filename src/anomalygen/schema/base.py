"""The ground every artefact stands on: the schema version, the two strict base classes, shared field
types, and readable validation errors.
"""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field, ValidationError

SCHEMA_VERSION = "1"
Vec3 = Annotated[list[float], Field(min_length=3, max_length=3)]
Quat = Annotated[list[float], Field(min_length=4, max_length=4, description="w, x, y, z")]
ScalarArg = str | float | int | bool


class Artefact(BaseModel):
    """Base for every stage artefact: strict, versioned, JSON round-trippable."""

    model_config = ConfigDict(extra="forbid", validate_assignment=True, populate_by_name=True)

    schema_version: str = SCHEMA_VERSION


class Strict(BaseModel):
    """Base for nested records: strict like artefacts, without their own version field."""

    model_config = ConfigDict(extra="forbid", validate_assignment=True)


def format_validation_error(err: ValidationError, *, limit: int = 5) -> str:
    """One readable line per problem, naming the offending field (used in CLI errors and LLM repair)."""
    lines = []
    for e in err.errors()[:limit]:
        loc = ".".join(str(p) for p in e["loc"]) or "<root>"
        if e["type"] == "extra_forbidden":
            lines.append(f"unknown field '{loc}' is not allowed")
        else:
            lines.append(f"{loc}: {e['msg']}")
    more = len(err.errors()) - limit
    if more > 0:
        lines.append(f"... and {more} more")
    return "; ".join(lines)
