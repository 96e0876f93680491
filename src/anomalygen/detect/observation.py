"""What the robot is shown: a compact rendering of ``scene_graph.json`` and nothing else.

Detection must find the hazard without being told the task, so the observation is built from the
perceived scene graph only (objects, their states and relations). The scene id and every field of
the task proposal stay out: a test checks that no n-gram of a task's name or description and no
hazard-class id leaks into the text. Clutter is rendered exactly like any other object, because the
robot cannot tell which objects matter.
"""

from __future__ import annotations

import json
from typing import Any

from anomalygen.schema import GraphObject, JointState, SceneGraph

# Below this distance to the edge of its support an object is called "near the edge" (same order as
# the knowledge base's near-edge predicate; the exact number stays visible in the rendering anyway).
NEAR_EDGE_M = 0.10


def joint_phrase(joint: JointState) -> str:
    """'door 80% open', 'drawer closed', 'knob on' — joint states as a person would say them."""
    frac = joint.open_fraction
    if joint.is_switch:
        return f"{joint.label} {'off' if joint.is_off() else 'on'}"
    if frac <= 0.02:
        return f"{joint.label} closed"
    return f"{joint.label} {round(frac * 100)}% open"


def object_facts(obj: GraphObject) -> list[str]:
    facts: list[str] = []
    if obj.on_floor:
        facts.append("on the floor")
    else:
        facts.append(f"{obj.height_above_floor:.2f} m above the floor")
    if obj.distance_to_edge is not None and not obj.on_floor:
        edge = f"{obj.distance_to_edge:.2f} m from the edge of its surface"
        facts.append(("near the edge, " + edge) if obj.distance_to_edge <= NEAR_EDGE_M else edge)
    if obj.child_reachable:
        facts.append("within a small child's reach")
    facts.extend(joint_phrase(j) for j in obj.joints)
    return facts


def relation_phrase(rel) -> str:
    if rel.predicate == "on_floor":
        return f"{rel.subject} is on the floor"
    words = {"on": "is on", "inside": "is inside", "near": "is near", "under": "is under", "blocks": "blocks"}
    text = f"{rel.subject} {words[rel.predicate]} {rel.object}"
    if rel.distance is not None:
        text += f" ({rel.distance:.2f} m)"
    return text


def observation_json(graph: SceneGraph) -> dict[str, Any]:
    """A JSON-ready dict of the observation (for structured prompts and for logging)."""
    objects = []
    for obj in graph.objects:
        item: dict[str, Any] = {
            "name": obj.name,
            "category": obj.category,
            "properties": list(obj.properties),
            "position": [round(v, 2) for v in obj.position],
            "size": [round(v, 2) for v in obj.size],
            "height_above_floor": round(obj.height_above_floor, 2),
            "on_floor": obj.on_floor,
            "child_reachable": obj.child_reachable,
        }
        if obj.distance_to_edge is not None:
            item["distance_to_edge"] = round(obj.distance_to_edge, 2)
            item["near_edge"] = (not obj.on_floor) and obj.distance_to_edge <= NEAR_EDGE_M
        if obj.joints:
            item["joints"] = [joint_phrase(j) for j in obj.joints]
        objects.append(item)
    relations = [relation_phrase(r) for r in graph.relations if r.predicate != "on_floor"]
    return {"room": graph.room, "objects": objects, "relations": relations}


def observation_text(graph: SceneGraph) -> str:
    """The readable rendering given to an LLM: one line per object, then the relations."""
    lines = [f"Room: {graph.room.replace('_', ' ')}", f"Objects ({len(graph.objects)}):"]
    for obj in graph.objects:
        props = f" [{', '.join(obj.properties)}]" if obj.properties else ""
        dims = "x".join(f"{v:.2f}" for v in obj.size)
        kind = f"{obj.called}: {obj.category}" if obj.called else obj.category  # "oven cleaner: cleaning_spray"
        lines.append(f"- {obj.name} ({kind}{props}), size {dims} m: " + "; ".join(object_facts(obj)))
    rels = [relation_phrase(r) for r in graph.relations if r.predicate != "on_floor"]
    if rels:
        lines.append("Relations:")
        lines.extend(f"- {r}" for r in rels)
    return "\n".join(lines)


def observation_json_text(graph: SceneGraph) -> str:
    return json.dumps(observation_json(graph), separators=(",", ":"))
