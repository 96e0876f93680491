"""Where fixtures and furniture belong in a home: the plausible-homes table.

Why: the generator chose a task's room from the object at fault alone, so a towel on a bathtub's
rim could be drawn in a kitchen and a toy beside a crib in a living room (issue 39 counted 64 such
fixtures in 1,000 tasks). A bathtub is not clutter: it stands against a bathroom wall and nowhere
else. ``data/knowledge/households.json`` lists, per fixture and piece of furniture, its rooms, how it
stands (against a wall, free, on a counter) and what its top is for. The generator draws only rooms
that every fixture a task names belongs to; a name the table does not hold is portable, and the
sampler draws it only in the rooms ``objects.json`` keeps it in (``IdeaSampler.found_in``). A ``top``
of "none" keeps the generator from drawing anything on that fixture (``holds_on_top``); ``mount`` is
recorded for the builder (fixtures against the walls of their room: not built yet).
"""

from __future__ import annotations

import functools
import json
from importlib.resources import files
from typing import Literal

from pydantic import BaseModel, ConfigDict

from anomalygen.knowledge.base import ROOMS


class Fixture(BaseModel):
    """One fixture or piece of furniture: the rooms it belongs to and how it stands in them."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    rooms: tuple[str, ...]
    mount: Literal["wall", "free", "counter", "floor"]
    top: str
    note: str = ""


class Households(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    fixtures: dict[str, Fixture]

    def rooms_of(self, name: str) -> tuple[str, ...] | None:
        """The rooms a fixture belongs to, or None for a portable thing (or a support kind: the floor)."""
        f = self.fixtures.get(name)
        return f.rooms if f is not None else None

    def belongs(self, name: str, room: str) -> bool:
        rooms = self.rooms_of(name)
        return rooms is None or room in rooms

    def misplaced_among(self, names, room: str) -> list[str]:
        """Those of ``names`` (once each, None skipped) that are fixtures not belonging in ``room``."""
        return [n for n in dict.fromkeys(names) if n and not self.belongs(n, room)]

    def misplaced(self, idea) -> list[str]:
        """The fixtures a brainstormed idea names that do not belong in its room."""
        p = idea.placement
        return self.misplaced_among([idea.hazard, p.support, p.other, idea.container, idea.support,
                                     *idea.co_objects], idea.room)

    def holds_on_top(self, name: str) -> bool:
        """Can something be set on ``name``? A fixture whose top is for nothing (a space heater's grille,
        a curtain) holds nothing on it; a portable thing or a support kind is left to the builder."""
        f = self.fixtures.get(name)
        return f is None or f.top != "none"

    def rooms_for(self, names, rooms) -> list[str]:
        """Those of ``rooms`` that every fixture among ``names`` belongs to, in the given order."""
        return [r for r in rooms if all(self.belongs(n, r) for n in names if n)]


@functools.cache
def load_households() -> Households:
    raw = json.loads(files("anomalygen.data.knowledge").joinpath("households.json").read_text("utf-8"))
    table = Households(fixtures=raw["fixtures"])
    unknown = sorted({r for f in table.fixtures.values() for r in f.rooms} - set(ROOMS))
    if unknown:
        raise ValueError(f"households.json names rooms that do not exist: {unknown}")
    return table


def named_objects(scenario) -> list[str]:
    """Every object and support a scenario names: the object at fault, its support, the placement's
    other object, the container and the co-objects."""
    p = scenario.placement
    out = [scenario.hazard_object, p.support if p is not None else None, p.other if p is not None else None,
           scenario.container, *scenario.co_objects]
    return [n for n in dict.fromkeys(out) if n]


def misplaced_objects(task) -> list[str]:
    """The fixtures a task names that do not belong in its room (an empty list for a plausible home)."""
    return load_households().misplaced_among(named_objects(task.scenario), task.scenario.room)
