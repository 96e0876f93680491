"""The one table of part labels: what each joint label means to the code that decides by it.

A joint's label names the part it moves (door, drawer, lid, knob, ...). The builder, the scene
graph, the predicates, the planners and the skills all decide by it: does the part shut something,
does it shut things out of reach, does it sweep out when open, is it an on/off control. They ask this
table and never spell a label themselves (``tests/test_part_labels.py`` fails on a literal copy),
so a new label is one row here, and no module can count a part as a closure that another ignores.

Labels in a scene spec are the knowledge base's words (:func:`canonical`): an asset's sash is its
window, a button its switch, a dial a knob, and an imported model's compound label (PartNet's
``rotation_door``) counts by its last word.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

# The labels the code decides by. Asset generators declare joints with these constants too.
DOOR = "door"
DRAWER = "drawer"
LID = "lid"
FLAP = "flap"  # a cardboard box's top: a lid in two halves
WINDOW = "window"
SASH = "sash"  # the moving part of a window
KNOB = "knob"
DIAL = "dial"
SWITCH = "switch"
BUTTON = "button"
TAP = "tap"
FAUCET = "faucet"
GATE = "gate"  # a safety gate: bars a way, holding nothing behind it
#: Not a joint label: the geom name of a pan's or pot's long handle, which the builder turns out over
#: the edge (world/states.py) and the rotate-inward skill turns back (skills/scripted/relocate.py).
HANDLE_GEOM = "handle"

# Labels of parts that move but that no rule of the code turns on (a blade, a wheel, a seat). They
# are listed so that every label the catalogue and the knowledge base use has a kind.
OTHER_PARTS = (
    "arm", "axis", "backrest", "blade", "cap", "hand", "handle", "hinge", "jaw", "key", "leg",
    "lever", "pedal", "pump", "rack", "rotor", "seat", "spin", "temple", "tray", "wheel",
)

CLOSED_TOL = 0.05  # open fraction at or below which a joint counts as closed, a switch as off
# A door left ajar by under 10 % of its travel still shuts a child out (and keeps what is inside apart
# from what is outside): looser than CLOSED_TOL, which asks whether the robot finished closing it.
ENCLOSED_TOL = 0.1


class PartKind(StrEnum):
    ENCLOSING = "enclosing"  # shuts a space: shut, what is behind it is out of reach (door, drawer, lid)
    CLOSURE = "closure"  # shuts an opening that holds nothing (a window)
    SWITCH = "switch"  # an on/off control; its closed value is off (knob, switch)
    OTHER = "other"  # moves, but decides nothing


@dataclass(frozen=True)
class PartLabel:
    """One row of the table."""

    name: str  # the knowledge base's word: what ``JointState.label`` holds and predicates ask for
    kind: PartKind
    swings: bool = False  # a hinged closure: it sweeps out in front of its object when open
    lid_like: bool = False  # opened and shut all at once from above (a lid, a box's flaps)
    aliases: tuple[str, ...] = ()  # asset labels that name this part in other words

    @property
    def is_closure(self) -> bool:
        return self.kind in (PartKind.ENCLOSING, PartKind.CLOSURE)


TABLE: tuple[PartLabel, ...] = (  # closures in the order the planner lists them ("lid|flap|drawer|door")
    PartLabel(LID, PartKind.ENCLOSING, swings=True, lid_like=True),
    PartLabel(FLAP, PartKind.ENCLOSING, swings=True, lid_like=True),
    PartLabel(DRAWER, PartKind.ENCLOSING),
    PartLabel(DOOR, PartKind.ENCLOSING, swings=True),
    PartLabel(WINDOW, PartKind.CLOSURE, swings=True, aliases=(SASH,)),
    PartLabel(GATE, PartKind.CLOSURE, swings=True),
    PartLabel(KNOB, PartKind.SWITCH, aliases=(DIAL,)),
    PartLabel(SWITCH, PartKind.SWITCH, aliases=(BUTTON,)),
    PartLabel(TAP, PartKind.SWITCH),
    PartLabel(FAUCET, PartKind.SWITCH),
    *(PartLabel(name, PartKind.OTHER) for name in OTHER_PARTS),
)

_BY_WORD: dict[str, PartLabel] = {w: row for row in TABLE for w in (row.name, *row.aliases)}


def part_label(label: str) -> PartLabel | None:
    """The table's row for a label, an alias or an imported compound label; None when unknown."""
    row = _BY_WORD.get(label)
    if row is None and "_" in label:
        row = _BY_WORD.get(label.rsplit("_", 1)[1])
    return row


def canonical(label: str) -> str:
    """The knowledge base's word for an asset's joint label (an unknown label stays as written)."""
    row = part_label(label)
    return row.name if row is not None else label


def kind_of(label: str) -> PartKind:
    row = part_label(label)
    return row.kind if row is not None else PartKind.OTHER


def is_closure(label: str) -> bool:
    """A part that shuts something: a door, drawer, lid, flap or window."""
    return kind_of(label) in (PartKind.ENCLOSING, PartKind.CLOSURE)


def encloses(label: str) -> bool:
    """A closure behind which an object is out of reach when it is shut (not a window)."""
    return kind_of(label) is PartKind.ENCLOSING


def is_switch(label: str) -> bool:
    """An on/off control: a knob, switch, button, dial or tap."""
    return kind_of(label) is PartKind.SWITCH


def swings(label: str) -> bool:
    """A hinged closure that sweeps out in front of its object when open."""
    row = part_label(label)
    return row is not None and row.swings


def any_of(labels) -> str:
    """Several labels as one predicate or sub-task argument: ``"lid|flap"``."""
    return "|".join(labels)


def alternatives(labels: str) -> list[str]:
    """The labels of an argument written ``"door|drawer"``."""
    return [x.strip() for x in labels.split("|") if x.strip()]


def _words(rows) -> tuple[str, ...]:
    return tuple(w for row in rows for w in (row.name, *row.aliases))


# Views of the table under the names the code has always used. Names only (JointState labels are
# canonical) unless the view says "and aliases" (asset labels, before the builder canonicalises them).
ENCLOSING_LABELS = tuple(row.name for row in TABLE if row.kind is PartKind.ENCLOSING)  # lid, flap, drawer, door
LID_LABELS = tuple(row.name for row in TABLE if row.lid_like)  # lid, flap
GATE_LABELS = (GATE,)
SWITCH_LABELS = tuple(row.name for row in TABLE if row.kind is PartKind.SWITCH)  # knob, switch, tap, faucet
CLOSURE_LABELS = _words(row for row in TABLE if row.is_closure)  # and aliases
SWINGING_CLOSURES = _words(row for row in TABLE if row.is_closure and row.swings)  # and aliases
