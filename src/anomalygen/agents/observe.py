"""What the skill-level env shows an agent: camera images, the textual scene description, the objects.

Everything comes from the robot's perception (``anomalygen.world``): the scene graph of the current
state, the perceived spec (no bindings, roles, validation report or task id) and renders. Keys:

- ``image``: the first camera's RGB (``cameras``, default the room's ``front`` camera; ``width`` x
  ``height``); further cameras as ``image_<camera>``;
- ``scene_text``: the paper's textual scene description, exactly what the LLM detector reads
  (:func:`anomalygen.detect.observation.observation_text`);
- ``objects``: the same as a structured list, one dict per object: ``name``, ``kind`` (its category),
  ``position`` and ``size`` (m), ``movable`` (1 unless fixed furniture), ``container`` (1 when it has an
  inside), ``states`` (the description's facts about it: "on the floor", "knob on", "lit", ...),
  ``parts`` (``name``, ``label``, ``state`` of each articulated part: what calls name) and
  ``relations`` ("on table_0", "inside drawer_0");
- ``graph`` (only when asked for): the scene graph itself, as a JSON dict (``schema.SceneGraph``):
  what the rule detector reads.
"""

from __future__ import annotations

import string

import numpy as np
from gymnasium import spaces

from anomalygen.schema import SceneGraph, SceneSpec

DEFAULT_OBSERVE = ("image", "scene_text", "objects")
KEYS = ("image", "scene_text", "objects", "graph")
CHARSET = frozenset(string.printable)
MAX_TEXT = 200_000  # characters of the scene description (a furnished room is a few thousand)
MAX_NAME = 256


def clean(text: str) -> str:
    """Text with any character outside the spaces' charset replaced (the spaces check every one)."""
    return "".join(c if c in CHARSET else "?" for c in text)


class GraphSpace(spaces.Space):
    """A scene graph as a JSON dict (``schema.SceneGraph``); asked for with ``observe=(..., "graph")``."""

    def __init__(self):
        super().__init__(shape=None, dtype=None)

    def contains(self, x) -> bool:
        if not isinstance(x, dict):
            return False
        try:
            SceneGraph.model_validate(x)
        except ValueError:
            return False
        return True

    @property
    def is_np_flattenable(self) -> bool:
        return False


def _text(n: int = MAX_NAME, min_length: int = 1) -> spaces.Text:
    return spaces.Text(max_length=n, min_length=min_length, charset="".join(sorted(CHARSET)))


def object_space() -> spaces.Dict:
    part = spaces.Dict({"name": _text(), "label": _text(), "state": _text()})
    return spaces.Dict({
        "name": _text(), "kind": _text(), "called": _text(min_length=0),
        "position": spaces.Box(-1e3, 1e3, shape=(3,), dtype=np.float64),
        "size": spaces.Box(0.0, 1e3, shape=(3,), dtype=np.float64),
        "movable": spaces.Discrete(2), "container": spaces.Discrete(2),
        "states": spaces.Sequence(_text(), stack=False),
        "parts": spaces.Sequence(part, stack=False),
        "relations": spaces.Sequence(_text(), stack=False),
    })


def observation_space(observe, cameras, width: int, height: int) -> spaces.Dict:
    unknown = sorted(set(observe) - set(KEYS))
    if unknown:
        raise ValueError(f"unknown observation keys {unknown}: the env observes {', '.join(KEYS)}")
    out: dict[str, spaces.Space] = {}
    if "image" in observe:
        for i, cam in enumerate(cameras):
            out["image" if i == 0 else f"image_{cam}"] = spaces.Box(0, 255, shape=(height, width, 3), dtype=np.uint8)
    if "scene_text" in observe:
        out["scene_text"] = _text(MAX_TEXT)
    if "objects" in observe:
        out["objects"] = spaces.Sequence(object_space(), stack=False)
    if "graph" in observe:
        out["graph"] = GraphSpace()
    return spaces.Dict(out)


def objects_of(graph: SceneGraph, spec: SceneSpec) -> tuple[dict, ...]:
    """The ``objects`` observation: every perceived object alike, in the graph's order."""
    from anomalygen.agents.vocabulary import part_name
    from anomalygen.detect.observation import joint_phrase, object_facts, relation_phrase

    placed = {o.name: o for o in spec.objects}
    rels: dict[str, list[str]] = {}
    for r in graph.relations:
        if r.predicate not in ("on_floor",) and r.object:
            rels.setdefault(r.subject, []).append(clean(relation_phrase(r).removeprefix(f"{r.subject} ")))
    out = []
    for o in graph.objects:
        p = placed.get(o.name)
        states = [*object_facts(o), *o.states, *(["held by the robot"] if o.held else [])]
        out.append({
            "name": clean(o.name), "kind": clean(o.category), "called": clean(o.called or ""),
            "position": np.asarray(o.position, dtype=np.float64), "size": np.asarray(o.size, dtype=np.float64),
            "movable": int(p is not None and not p.fixed),
            "container": int(p is not None and bool(p.cavities)),
            "states": tuple(clean(s) for s in states),
            "parts": tuple({"name": clean(part_name(j.name)), "label": clean(j.label), "state": clean(joint_phrase(j))}
                           for j in o.joints),
            "relations": tuple(rels.get(o.name, ())),
        })
    return tuple(out)


def observe(graph: SceneGraph, spec: SceneSpec, keys, images: dict[str, np.ndarray]) -> dict:
    """One observation (fresh objects every call: an agent may keep what it was given)."""
    from anomalygen.detect.observation import observation_text

    obs: dict = {}
    if "image" in keys:
        for i, (cam, img) in enumerate(images.items()):
            obs["image" if i == 0 else f"image_{cam}"] = np.array(img, dtype=np.uint8, copy=True)
    if "scene_text" in keys:
        obs["scene_text"] = clean(observation_text(graph))
    if "objects" in keys:
        obs["objects"] = objects_of(graph, spec)
    if "graph" in keys:
        obs["graph"] = graph.model_dump(mode="json")
    return obs
