"""What the scene builder can set up, for the stages that propose scenes (brainstorming draws only
what can be built; a user's line that needs more fails saying so).

Kept in one small module so that whoever teaches the builder a new placement or state adds it here
in the same change, and the brainstorm engine draws it from then on without being edited.
"""

from __future__ import annotations

from anomalygen.world.states import KNOWN_STATES

#: Placement kinds ``scene/placement.py`` implements (``inside``/``on``/``near`` take ``:<name>``).
PLACEMENT_KINDS: tuple[str, ...] = (
    "floor", "walkway", "table", "low_table", "table_edge", "counter", "counter_edge", "shelf", "shelf_edge",
    "inside", "on", "near",
)
#: Instance states the builder puts into a scene when a task or its class asks for them
#: (``scene/set_states.py``; the words live in ``world/states.py``). States an asset always shows come
#: from the knowledge base (``ObjectInfo.states``).
BUILT_STATES: tuple[str, ...] = KNOWN_STATES


def placement_kind(placement: str) -> str:
    """``near:Crib`` -> ``near``; ``table_edge`` -> ``table_edge``."""
    return placement.split(":", 1)[0]


def can_place(placement: str) -> bool:
    return placement_kind(placement) in PLACEMENT_KINDS


def can_show(state: str) -> bool:
    return state in BUILT_STATES
