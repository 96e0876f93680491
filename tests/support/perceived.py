"""A scene graph for a hand-made SceneSpec, so plan tests can give the robot something to perceive."""

from __future__ import annotations

from anomalygen.schema import GraphObject, SceneGraph, SceneSpec


def graph_of(spec: SceneSpec) -> SceneGraph:
    """Each placed object as a cube of its size at its position (enough for binding roles by kind and distance)."""
    objects = []
    for o in spec.objects:
        z = float(o.pos[2])
        objects.append(GraphObject(name=o.name, category=o.asset.category, properties=[], position=list(o.pos),
                                   size=[o.size] * 3, height_above_floor=max(0.0, z - o.size / 2),
                                   on_floor=z - o.size / 2 < 0.01, child_reachable=z <= 1.0,
                                   joints=list(o.joint_states)))
    return SceneGraph(scene_id=spec.scene_id, room=spec.room, objects=objects)
