"""Where a scenario puts its object: a ``Placement``, one relation to a support kind or to another object.

``on`` a support kind (the floor, a low table, a table, a counter, a shelf), ``at_edge`` of one (half off
the counter), in the ``walkway`` (on the floor where people walk), or ``inside``, ``on`` or ``near``
another catalogue object (the bathtub, the stove, the sink).

Placements used to be compact words, and run folders, the knowledge data files and LLM replies still
hold them: ``counter_edge``, ``walkway``, ``inside:Bathtub``. ``Placement`` reads them (this module is
the only one that parses that form) and gives the word back as ``key`` (also ``str()``) for what needs
the word itself: phrase tables keyed by it, grounding vocabularies, ids and log lines. Logic reads the
fields.

Adding a relation kind: one ``RelationKind`` line in ``RELATIONS`` (its name, the support kinds it
takes, whether it names another object, its compact word), plus its builder code in
``scene/placement.py::_place_hazard`` (and, where it reads differently, its phrases in
``brainstorm/realise.py`` and its synthetic scene in ``detect/kbcheck.py``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, get_args

from pydantic import BaseModel, ConfigDict, Field, model_validator

#: The support kinds, from the floor up: the furniture surfaces a placement can stand on.
SupportKind = Literal["floor", "low_table", "table", "counter", "shelf"]
SUPPORT_KINDS: tuple[str, ...] = get_args(SupportKind)
#: The knowledge data's slot for the object a composed class relates its object to (``near:{other}``).
OTHER_SLOT = "{other}"


@dataclass(frozen=True)
class RelationKind:
    """One relation a placement can state, and what it relates the object to."""

    name: str
    supports: tuple[str, ...] = ()  # the support kinds it takes (empty: none)
    names_other: bool = False  # it relates the object to another catalogue object
    word: str = "{support}"  # its compact word with a support kind


#: The relation kinds, the one list: every other view (the words, the kinds taking an object) derives from it.
RELATIONS: tuple[RelationKind, ...] = (
    RelationKind("on", supports=SUPPORT_KINDS, names_other=True),  # "table", "floor"; "on:Stove"
    RelationKind("at_edge", supports=("table", "counter", "shelf"), word="{support}_edge"),  # "counter_edge"
    RelationKind("walkway", supports=("floor",), word="walkway"),  # on the floor where people walk
    RelationKind("inside", names_other=True),  # "inside:Bathtub"
    RelationKind("near", names_other=True),  # "near:Sink": beside it, on the floor or the same support
)
RELATION_KINDS: dict[str, RelationKind] = {r.name: r for r in RELATIONS}
RelationName = Literal[tuple(RELATION_KINDS)]  # the names of RELATIONS (derived: the field's type and schema enum)
#: The relations that name another object, in the list's order.
OBJECT_RELATIONS: tuple[str, ...] = tuple(r.name for r in RELATIONS if r.names_other)
#: Compact word -> (relation, support kind), support kinds from the floor up.
_WORDS: dict[str, tuple[str, str]] = {
    r.word.format(support=s): (r.name, s) for s in SUPPORT_KINDS for r in RELATIONS if s in r.supports
}
assert len(_WORDS) == sum(len(r.supports) for r in RELATIONS), "two relations spell one word"


def _forms() -> str:
    return ", ".join([*_WORDS, *(f"{r}:<object>" for r in OBJECT_RELATIONS)])


def _read(text: str) -> dict[str, str]:
    """The fields of a compact placement (``counter_edge``, ``near:Sink``); a ValueError saying why not."""
    relation, colon, other = text.partition(":")
    if colon:
        if relation not in OBJECT_RELATIONS:
            raise ValueError(f"placement '{text}': '{relation}' is not a relation to another object "
                             f"({', '.join(OBJECT_RELATIONS)})")
        return {"relation": relation, "other": other}
    if text not in _WORDS:
        raise ValueError(f"placement '{text}' is not one of {_forms()}")
    relation, support = _WORDS[text]
    return {"relation": relation, "support": support}


def object_relation(written: str) -> tuple[str, str] | None:
    """(relation, the object as written) of a compact ``relation:object`` text, the object not checked
    against anything (the grounder resolves it); None when the text is not of that form."""
    relation, colon, other = written.partition(":")
    return (relation, other) if colon and relation in OBJECT_RELATIONS else None


def _shapes_schema(schema: dict[str, Any]) -> None:
    """The JSON schema states each relation's valid shapes (``on`` with a support kind, ``on`` with an
    object, ...), one ``anyOf`` branch each, derived from ``RELATIONS``: a grammar-constrained model
    (and a schema that keeps only required fields) then cannot write ``on`` with neither."""
    shapes = []
    for r in RELATIONS:
        relation = {"const": r.name}
        if r.supports:
            shapes.append({"type": "object", "additionalProperties": False, "required": ["relation", "support"],
                           "properties": {"relation": relation,
                                          "support": {"type": "string", "enum": list(r.supports)}}})
        if r.names_other:
            shapes.append({"type": "object", "additionalProperties": False, "required": ["relation", "other"],
                           "properties": {"relation": relation,
                                          "other": {"type": "string", "description": "catalogue name of the other object"}}})
    for key in ("properties", "required", "additionalProperties", "type"):
        schema.pop(key, None)
    schema["anyOf"] = shapes


class Placement(BaseModel):
    """Where the object is: one relation (``RELATIONS``) to a support kind or to another catalogue object.

    ``on`` + ``table``; ``at_edge`` + ``counter``; ``walkway`` (on the ``floor``); ``inside`` + ``Bathtub``;
    ``on`` + ``Stove``; ``near`` + ``Sink``. Reads the compact words too (``counter_edge``, ``inside:Bathtub``).
    """

    model_config = ConfigDict(extra="forbid", frozen=True, json_schema_extra=_shapes_schema)

    relation: RelationName = Field(description=", ".join(RELATION_KINDS))
    support: SupportKind | None = Field(None, description="the support kind it is on or at the edge of")
    other: str | None = Field(None, description="catalogue name of the object it is inside, on or near")

    @model_validator(mode="before")
    @classmethod
    def _compact(cls, data: Any) -> Any:
        """A compact word reads as its fields; a relation with one support kind (walkway) takes it."""
        if isinstance(data, str):
            return _read(data)
        if isinstance(data, dict) and data.get("support") is None and data.get("other") is None:
            relation = data.get("relation")
            kind = RELATION_KINDS.get(relation) if isinstance(relation, str) else None
            if kind is not None and len(kind.supports) == 1 and not kind.names_other:
                return {**data, "support": kind.supports[0]}
        return data

    @model_validator(mode="after")
    def _possible(self) -> Placement:
        kind = RELATION_KINDS[self.relation]
        if self.support is not None and self.other is not None:
            raise ValueError(f"placement '{self.relation}' relates to a support kind or to another object, "
                             f"not both ({self.support}, {self.other})")
        if self.other is not None:
            if not kind.names_other:
                raise ValueError(f"placement '{self.relation}' names no other object (got '{self.other}')")
            if not self.other:
                raise ValueError(f"placement '{self.relation}' needs the name of the other object")
        elif self.support is None:
            wants = [f"a support kind ({', '.join(kind.supports)})"] if kind.supports else []
            wants += ["the name of another object"] if kind.names_other else []
            raise ValueError(f"placement '{self.relation}' needs {' or '.join(wants)}")
        elif self.support not in kind.supports:
            takes = f"takes {', '.join(kind.supports)}" if kind.supports else "takes no support kind"
            raise ValueError(f"placement '{self.relation}' {takes}, not '{self.support}'")
        return self

    @property
    def key(self) -> str:
        """The compact word: ``counter_edge``, ``walkway``, ``inside:Bathtub`` (phrase tables, ids, logs)."""
        if self.other is not None:
            return f"{self.relation}:{self.other}"
        return RELATION_KINDS[self.relation].word.format(support=self.support)

    def __str__(self) -> str:
        return self.key

    @property
    def furniture(self) -> str | None:
        """The raised support kind it stands on or at the edge of (a table, a counter, a shelf); None on
        the floor or with another object."""
        return self.support if self.support != "floor" else None

    def filled(self, other: str) -> Placement:
        """This placement with the knowledge data's ``{other}`` slot filled by ``other`` (else itself)."""
        return Placement(relation=self.relation, other=other) if self.other == OTHER_SLOT else self


#: Every placement on or at a support kind, from the floor up (the words without another object).
SUPPORT_PLACEMENTS: tuple[Placement, ...] = tuple(Placement(relation=r, support=s) for r, s in _WORDS.values())
