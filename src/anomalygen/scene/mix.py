"""Scenes that test judgement: near-miss distractors and a second hazard.

Why: when every scene holds exactly one hazard and nothing that looks like one, a detector that
names the most alarming object scores perfectly without judging anything. So the builder adds

- **near-misses**: hazard-class objects in a safe state; here, fragile or heavy things standing well
  inside a table top (``INWARD`` from every edge, beyond the knowledge base's edge distance), which a
  careless detector would flag and a careful one leaves alone;
- **a second hazard**, in ``build.multi_hazard`` of the scenes: a piece of litter on the floor, with a
  bin in the room so the robot can fix it;
- **no hazard at all**, in ``build.hazard_free`` of the scenes: the task's object is built in its safe
  state instead (shut in its container, well inside its surface, its door or lid closed), so the
  scene holds a near-miss where the hazard would have been.

Every draw comes from a generator of its own (``item_rng(seed, task, "mix")``), so with both
features off a scene is exactly what it was without this module. Whatever ends up hazardous or safe
is read back from the settled scene by ``scene.truth``, so the manifest never trusts these intentions.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from anomalygen.rng import item_rng

if TYPE_CHECKING:
    from anomalygen.config import Settings

NEAR_MISS_PROPERTIES = {"fragile", "heavy"}  # safe when well away from an edge
NEAR_MISS_EXCLUDED = {"hot", "sharp", "toxic", "medication", "flammable", "perishable", "spoiled", "litter",
                      "choking_size", "cable", "furniture", "appliance"}  # a class fires on these anywhere reachable
SECOND_HAZARD_CLASS = "pick_up_floor_litter"
MAX_ITEM_SIZE = 0.3  # m: near-misses and the second hazard are hand-sized


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


@dataclass
class JudgementItems:
    """What to add to one scene (the builder places them): catalogue names and a generator to draw with."""

    near_misses: list[str] = field(default_factory=list)
    second_hazard: str | None = None
    bin: str | None = None  # a container for the second hazard, when the scene has none
    rng: np.random.Generator | None = None


def choose_judgement_items(task_id: str, hazard_class: str, in_scene: set[str], kb, settings: Settings,
                           *, hazard_free: bool = False) -> JudgementItems:
    """The near-misses and second hazard for one scene, drawn from the scene's own mix generator
    (a hazard-free scene gets no second hazard: it is meant to hold none)."""
    cfg = settings.build
    rng = item_rng(settings.seed, task_id, "mix")
    items = JudgementItems(rng=rng)
    names = near_miss_names(kb, in_scene)
    if names and cfg.near_misses > 0:
        picks = rng.choice(len(names), size=min(cfg.near_misses, len(names)), replace=False)
        items.near_misses = [names[i] for i in sorted(picks)]
    second = rng.random() < cfg.multi_hazard if cfg.multi_hazard > 0 else False
    if second and not hazard_free and hazard_class != SECOND_HAZARD_CLASS:
        hc = kb.hazard_classes[SECOND_HAZARD_CLASS]
        cands = [n for n in kb.hazard_candidates(hc) if n not in in_scene
                 and kb.objects[n].size_range[0] <= MAX_ITEM_SIZE]
        if cands:
            items.second_hazard = cands[int(rng.integers(len(cands)))]
            bins = [c for c in hc.default_containers if c in kb.objects]
            if bins and not set(bins) & in_scene:
                items.bin = bins[0]
    return items


def is_hazard_free(task_id: str, settings: Settings) -> bool:
    """Whether this task's scene is built with its hazard made safe (``build.hazard_free`` of the scenes)."""
    share = settings.build.hazard_free
    return share > 0 and float(item_rng(settings.seed, task_id, "hazard-free").random()) < share
