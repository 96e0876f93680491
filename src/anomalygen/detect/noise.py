"""Optional perception noise on the scene graph a detector reads (``detect.noise``, off by default).

Why: the scene graph comes straight from the simulator, so rules over it are an oracle-perception
baseline. A real perceiver misplaces objects a little, misses small ones and mistakes look-alikes;
with noise on, the detectors are measured off that perfect graph too. Only what the detector reads
changes: the judge, the plan and the skills keep the simulator's graph.

Three kinds, each drawn per object from one generator per scene (``item_rng(run seed, NOISE_KEY,
scene id)``), six numbers per object in name order whatever happens, so one object's outcome never
shifts another's:

- *pose jitter*: the object's position moves by up to ``pose_jitter`` metres per axis (uniform);
  what the graph derives from its box moves with it: height above the floor, the distance to the
  edge of what it rests on (against that support's own jittered box), a child's reach (the graph's
  rule at the new height; a latch the graph does not record is read off the true answer), and the
  ``near`` relations (re-measured box to box);
- *missed small objects*: an object whose largest extent is at most ``small_size`` is left out,
  with its relations, with probability ``miss_rate``;
- *category confusions*: an object whose category has look-alikes in the knowledge base
  (``data/knowledge/lookalikes.json``) is seen, with probability ``confusion_rate``, as one of them,
  with that one's properties. Its instance name stays: it is the handle the robot acts through.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from anomalygen.knowledge.predicates import aabb_gap
from anomalygen.rng import item_rng
from anomalygen.schema import (
    CHILD_REACH,
    GraphObject,
    PerceptionNoise,
    Relation,
    SceneGraph,
    within_child_reach,
)
from anomalygen.world.graph import NEAR_DIST

if TYPE_CHECKING:
    from anomalygen.config import NoiseConfig, Settings
    from anomalygen.knowledge import KnowledgeBase

NOISE_KEY = "detect.noise"
_CONTACT = ("on", "inside")  # relations between objects that touch: never "near" (as in the scene graph)


def detector_graph(graph: SceneGraph, settings: Settings) -> tuple[SceneGraph, PerceptionNoise | None]:
    """What the detector reads: the graph itself with noise off (no record), else its noisy copy."""
    cfg = settings.detect.noise
    if not cfg.enabled:
        return graph, None
    from anomalygen.knowledge import load_kb

    return add_noise(graph, cfg, noise_rng(settings.seed, graph.scene_id), load_kb(), settings.seed)


def noise_rng(seed: int, scene_id: str) -> np.random.Generator:
    return item_rng(seed, NOISE_KEY, scene_id)


def add_noise(graph: SceneGraph, cfg: NoiseConfig, rng: np.random.Generator, kb: KnowledgeBase,
              seed: int) -> tuple[SceneGraph, PerceptionNoise]:
    """The graph as a noisy perceiver would report it, and the record of the settings and counts."""
    draws = {o.name: (rng.random(), rng.random(), rng.random(), rng.uniform(-1.0, 1.0, 3)) for o in graph.objects}
    shift = {name: d[3] * cfg.pose_jitter for name, d in draws.items()}
    missed = {o.name for o in graph.objects
              if max(o.size) <= cfg.small_size and draws[o.name][0] < cfg.miss_rate}
    by_name = {o.name: o for o in graph.objects}
    kept, confused = [], 0
    for obj in graph.objects:
        if obj.name in missed:
            continue
        _, u_confuse, u_pick, _ = draws[obj.name]
        seen = _jittered(obj, shift, graph, by_name)
        others = kb.lookalikes(obj.category)
        if others and u_confuse < cfg.confusion_rate:
            other = others[min(int(u_pick * len(others)), len(others) - 1)]
            seen = seen.model_copy(update={"category": other, "properties": kb.properties_of(other)})
            confused += 1
        kept.append(seen)
    relations = [r for r in graph.relations
                 if r.predicate != "near" and r.subject not in missed and _instance(r.object) not in missed]
    relations += _near(kept, relations)
    record = PerceptionNoise(pose_jitter=cfg.pose_jitter, miss_rate=cfg.miss_rate, small_size=cfg.small_size,
                             confusion_rate=cfg.confusion_rate, seed=seed, objects=len(graph.objects),
                             missed=len(missed), confused=confused)
    return graph.model_copy(update={"objects": kept, "relations": relations}), record


def _instance(ref: str | None) -> str:
    """``counter_0:top`` -> ``counter_0`` (a relation may name a surface of an object)."""
    return (ref or "").split(":", 1)[0]


def _jittered(obj: GraphObject, shift: dict[str, np.ndarray], graph: SceneGraph,
              by_name: dict[str, GraphObject]) -> GraphObject:
    d = shift[obj.name]
    height = max(0.0, obj.height_above_floor + float(d[2]))
    inside = any(r.subject == obj.name and r.predicate == "inside" for r in graph.relations)
    edge = obj.distance_to_edge
    if edge is not None:
        edge += _edge_change(obj, shift, graph, by_name)
    return obj.model_copy(update={
        "position": [float(v) for v in np.asarray(obj.position) + d],
        "height_above_floor": height,
        "child_reachable": _reachable(obj, height, inside),
        "distance_to_edge": edge,
    })


def _reachable(obj: GraphObject, height: float, inside: bool) -> bool:
    """A child's reach at the jittered height, by the scene graph's own rule (``within_child_reach``).
    Whether the object is shut in a latching container is not in the graph: when its true bottom is
    within reach, the true answer tells it (only a latch keeps a low object out); when it is higher
    and inside something, it cannot be told, so the object keeps its true answer."""
    if not inside:
        return within_child_reach(height, False)
    if obj.height_above_floor <= CHILD_REACH:
        return within_child_reach(height, not obj.child_reachable)
    return obj.child_reachable


def _edge_change(obj: GraphObject, shift: dict[str, np.ndarray], graph: SceneGraph,
                 by_name: dict[str, GraphObject]) -> float:
    """How much the distance to the nearest edge of the support's top changes when both boxes move:
    the nearest edge is found on the true boxes, its gap re-measured on the jittered ones."""
    supports = [by_name[s] for r in graph.relations
                if r.subject == obj.name and r.predicate == "on" and (s := _instance(r.object)) in by_name]
    if not supports:
        return 0.0
    sup = max(supports, key=lambda s: s.size[0] * s.size[1])
    o_lo = np.asarray(obj.position[:2]) - np.asarray(obj.size[:2]) / 2
    o_hi = o_lo + np.asarray(obj.size[:2])
    s_lo = np.asarray(sup.position[:2]) - np.asarray(sup.size[:2]) / 2
    s_hi = s_lo + np.asarray(sup.size[:2])
    gaps = np.r_[o_lo - s_lo, s_hi - o_hi]  # x-low, y-low, x-high, y-high
    k = int(np.argmin(gaps))
    relative = shift[obj.name][:2] - shift[sup.name][:2]
    return float(relative[k % 2] if k < 2 else -relative[k % 2])


def _near(objects: list[GraphObject], relations: list[Relation]) -> list[Relation]:
    touching = {frozenset((r.subject, _instance(r.object))) for r in relations if r.predicate in _CONTACT}
    out = []
    for i, a in enumerate(objects):
        for b in objects[i + 1:]:
            if frozenset((a.name, b.name)) in touching:
                continue
            gap = aabb_gap(a, b)
            if gap < NEAR_DIST:
                out.append(Relation(subject=a.name, predicate="near", object=b.name, distance=round(gap, 4)))
    return out
