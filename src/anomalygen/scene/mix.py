"""Scenes that test judgement: near-miss distractors and a second hazard.

Why: when every scene holds exactly one hazard and nothing that looks like one, a detector that
names the most alarming object scores perfectly without judging anything. So the builder adds

- **near-misses**: hazard-class objects in a safe state, which a careless detector would flag and a
  careful one leaves alone. Fragile or heavy things stand on a table top either well clear of every
  edge (``far``) or on the borderline of the knowledge base's edge rule: ``BORDER_M`` outside it (a
  near-miss) or ``BORDER_M`` inside it (a real hazard, listed in the truth as an intended one). A
  *state* near-miss is an object whose class is about a part's state, left safe: a kettle switched
  off, a box whose lid is ajar by ``AJAR_RAD``;
- **a second hazard**, in ``build.multi_hazard`` of the scenes: a piece of litter on the floor, with a
  bin in the room so the robot can fix it;
- **no hazard at all**, in ``build.hazard_free`` of the scenes: the task's object is built in its safe
  state instead (shut in its container, well inside its surface, its door or lid closed), so the
  scene holds a near-miss where the hazard would have been.

A user's own line (``TaskProposal.source == "user_text"``) is built as stated: never hazard-free and
never given a second hazard (near-misses, which are safe, still dress it).

Every draw comes from a generator of its own (``item_rng(seed, task, "mix")``, the kinds and the state
near-miss from ``item_rng(seed, task, "mix-kinds")``), so with the features off a scene is exactly what
it was without this module. What the mix meant each item to be goes to the truth manifest as an
intent; whatever ends up hazardous or safe is read back from the settled scene, so a meant hazard that
did not come about is listed as a borderline near-miss, never as a hazard.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from anomalygen.rng import item_rng
from anomalygen.schema import part_labels

if TYPE_CHECKING:
    from anomalygen.config import Settings

NEAR_MISS_PROPERTIES = {"fragile", "heavy"}  # safe when well away from an edge
NEAR_MISS_EXCLUDED = {"hot", "sharp", "toxic", "medication", "flammable", "perishable", "spoiled", "litter",
                      "choking_size", "cable", "furniture", "appliance"}  # a class fires on these anywhere reachable
SECOND_HAZARD_CLASS = "pick_up_floor_litter"
MAX_ITEM_SIZE = 0.3  # m: near-misses and the second hazard are hand-sized
MAX_STATE_ITEM_SIZE = 0.35  # m: a state near-miss (a kettle, a box) still fits on a side table
# Near-miss kinds and how often each is drawn: well clear of the edge rule, just outside it, or just
# inside it (then it is a real hazard the robot has to find and fix).
NEAR_MISS_KINDS = ("far", "just_outside", "just_inside")
NEAR_MISS_KIND_P = (0.4, 0.4, 0.2)
BORDER_M = 0.01  # m either side of a class's distance threshold (0.11 and 0.13 m for a 0.12 m rule)
FAR_M = 0.25  # m from every edge for a near-miss well clear of the edge rule
NEAR_FAR_M = 0.15  # m: the fallback on a crowded top, still 3 cm beyond the 0.12 m edge rule
STATE_NEAR_MISS_SHARE = 0.5  # share of scenes given a state near-miss (when near_misses > 0)
AJAR_RAD = math.radians(2.0)  # a door or lid left ajar by two degrees: shut in every class's sense
AJAR_M = 0.005  # m: a drawer left out by half a centimetre


def near_miss_names(kb, exclude: set[str]) -> list[str]:
    """Catalogue objects that look like a hazard class's object but are safe on a table's middle."""
    from anomalygen.scene.asset_choice import catalogue_names

    out = []
    for name in catalogue_names():
        info = kb.objects.get(name)
        if info is None or info.kind != "household" or name in exclude:
            continue
        props = set(info.properties)
        if props & NEAR_MISS_PROPERTIES and not props & NEAR_MISS_EXCLUDED and info.size_range[0] <= MAX_ITEM_SIZE:
            out.append(name)
    return out


def edge_threshold(kb, category: str) -> tuple[str, float] | None:
    """(class, metres) of the tightest edge rule (``near_edge``) a class applies to ``category``."""
    best = None
    for hc_id in sorted(kb.hazard_classes):
        hc = kb.hazard_classes[hc_id]
        if category not in kb.hazard_candidates(hc):
            continue
        for call in hc.preconditions:
            if call.name == "near_edge" and not call.negate:
                limit = float(call.args.get("max_distance", 0.1))
                if best is None or limit < best[1]:
                    best = (hc_id, limit)
    return best


def state_near_miss_names(kb, exclude: set[str]) -> list[tuple[str, str, str]]:
    """(catalogue name, class, part labels) of hand-sized objects a class flags by a part's state
    (``joint_open``): a kettle's switch, a box's lid. Built with the part safe, they are near-misses."""
    from anomalygen.scene.asset_choice import catalogue_names

    out = []
    names = set(catalogue_names())
    for hc_id in sorted(kb.hazard_classes):
        hc = kb.hazard_classes[hc_id]
        opens = [c for c in hc.preconditions if c.name == "joint_open" and not c.negate]
        if not opens:
            continue
        for name in sorted(kb.hazard_candidates(hc)):
            info = kb.objects.get(name)
            if name in names and name not in exclude and info is not None and info.size_range[0] <= MAX_STATE_ITEM_SIZE:
                out.append((name, hc_id, str(opens[0].args.get("label", "*"))))
    return out


@dataclass(frozen=True)
class NearMissPick:
    """One near-miss to place: its catalogue name, kind, and for borderline kinds the class whose edge
    rule it straddles and the footprint's distance from the edge that faces the robot."""

    category: str
    kind: str  # far | just_outside | just_inside
    hazard_class: str | None = None
    edge_gap: float | None = None  # m


@dataclass(frozen=True)
class StatePick:
    """A state near-miss: the object, the class it resembles, the part labels, the part's safe value."""

    category: str
    hazard_class: str
    labels: str  # 'door|lid' style alternatives of the class's joint_open
    ajar: bool  # doors, lids, drawers a hair open; knobs and switches exactly off


@dataclass
class JudgementItems:
    """What to add to one scene (the builder places them): catalogue names and a generator to draw with."""

    near_misses: list[NearMissPick] = field(default_factory=list)
    second_hazard: str | None = None
    bin: str | None = None  # a container for the second hazard, when the scene has none
    bin_kinds: list[str] = field(default_factory=list)  # every kind the planner would put it in
    state: StatePick | None = None
    rng: np.random.Generator | None = None


USER_TEXT = "user_text"  # TaskProposal.source of a user's plain line: built as stated


def choose_judgement_items(task_id: str, hazard_class: str, in_scene: set[str], kb, settings: Settings,
                           *, hazard_free: bool = False, source: str = "engine") -> JudgementItems:
    """The near-misses and second hazard for one scene, drawn from the scene's own mix generator
    (a hazard-free scene gets no second hazard: it is meant to hold none; nor does a user's line)."""
    cfg = settings.build
    rng = item_rng(settings.seed, task_id, "mix")
    items = JudgementItems(rng=rng)
    names = near_miss_names(kb, in_scene)
    if names and cfg.near_misses > 0:
        picks = rng.choice(len(names), size=min(cfg.near_misses, len(names)), replace=False)
        kinds_rng = item_rng(settings.seed, task_id, "mix-kinds")
        items.near_misses = [_near_miss(kb, names[i], kinds_rng, hazard_free) for i in sorted(picks)]
        states = state_near_miss_names(kb, in_scene)
        if states and kinds_rng.random() < STATE_NEAR_MISS_SHARE:
            name, hc_id, labels = states[int(kinds_rng.integers(len(states)))]
            ajar = any(part_labels.is_closure(lbl) for lbl in part_labels.alternatives(labels))
            items.state = StatePick(name, hc_id, labels, ajar)
    second = rng.random() < cfg.multi_hazard if cfg.multi_hazard > 0 else False
    if second and not hazard_free and hazard_class != SECOND_HAZARD_CLASS and source != USER_TEXT:
        hc = kb.hazard_classes[SECOND_HAZARD_CLASS]
        cands = [n for n in kb.hazard_candidates(hc) if n not in in_scene
                 and kb.objects[n].size_range[0] <= MAX_ITEM_SIZE]
        if cands:
            items.second_hazard = cands[int(rng.integers(len(cands)))]
            # the kinds the robot's planner will look for (``bind.choose_container`` asks the same
            # question): a bucket in the room is no bin for a plastic bag the knowledge base throws away
            items.bin_kinds = [c for c in kb.containers_for(hc, items.second_hazard) if c in kb.objects]
            if items.bin_kinds and not set(items.bin_kinds) & in_scene:
                items.bin = items.bin_kinds[0]
    return items


def _near_miss(kb, name: str, rng: np.random.Generator, hazard_free: bool) -> NearMissPick:
    """Draw a kind for one near-miss; borderline kinds sit ``BORDER_M`` either side of its edge rule
    (a hazard-free scene gets none just inside: it is meant to hold no hazard)."""
    kind = NEAR_MISS_KINDS[int(rng.choice(len(NEAR_MISS_KINDS), p=NEAR_MISS_KIND_P))]
    rule = edge_threshold(kb, name)
    if kind == "far" or rule is None:
        return NearMissPick(name, "far")
    if kind == "just_inside" and hazard_free:
        kind = "just_outside"
    gap = rule[1] + (BORDER_M if kind == "just_outside" else -BORDER_M)
    return NearMissPick(name, kind, rule[0], round(gap, 4))


def is_hazard_free(task_id: str, settings: Settings, *, source: str = "engine") -> bool:
    """Whether this task's scene is built with its hazard made safe (``build.hazard_free`` of the scenes;
    never a user's own line)."""
    share = settings.build.hazard_free if source != USER_TEXT else 0.0
    return share > 0 and float(item_rng(settings.seed, task_id, "hazard-free").random()) < share
