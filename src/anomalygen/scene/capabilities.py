"""What the scene builder can set up, for the stages that propose scenes (brainstorming draws only
what can be built; a user's line that needs more fails saying so).

Kept in one small module so that whoever teaches the builder a new state adds it here in the same
change, and the brainstorm engine draws it from then on without being edited. Placements have no list
here: the builder (``scene/placement.py``) builds every relation kind of ``schema/placement.py``'s
``RELATIONS``, so a new kind comes with its builder code in the same change.
"""

from __future__ import annotations

from anomalygen.world.states import KNOWN_STATES

#: Instance states the builder puts into a scene when a task or its class asks for them
#: (``scene/set_states.py``; the words live in ``world/states.py``). States an asset always shows come
#: from the knowledge base (``ObjectInfo.states``).
BUILT_STATES: tuple[str, ...] = KNOWN_STATES


def can_show(state: str) -> bool:
    return state in BUILT_STATES
