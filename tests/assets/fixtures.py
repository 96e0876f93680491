"""Writers for small on-disk fixtures in the exact PartNet-Mobility and Objaverse layouts."""

from __future__ import annotations

import json
from pathlib import Path


def write_box_obj(path: Path, hx: float, hy: float, hz: float, center=(0.0, 0.0, 0.0)) -> Path:
    """A closed box mesh as a Wavefront OBJ (8 vertices, 12 triangles)."""
    cx, cy, cz = center
    v = [(cx + sx * hx, cy + sy * hy, cz + sz * hz) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
    faces = [
        (1, 3, 4),
        (1, 4, 2),
        (5, 6, 8),
        (5, 8, 7),
        (1, 2, 6),
        (1, 6, 5),
        (3, 7, 8),
        (3, 8, 4),
        (1, 5, 7),
        (1, 7, 3),
        (2, 4, 8),
        (2, 8, 6),
    ]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(
        "".join(f"v {x} {y} {z}\n" for x, y, z in v) + "".join(f"f {a} {b} {c}\n" for a, b, c in faces)
    )
    return path


def write_partnet_cabinet(folder: Path, anno_id: str = "45135") -> Path:
    """A one-door cabinet in PartNet-Mobility layout (Y-up, package:// mesh paths, hinge + slider)."""
    objs = folder / "textured_objs"
    write_box_obj(objs / "original-1.obj", 0.3, 0.4, 0.2)  # body (x, y-up, z)
    write_box_obj(
        objs / "original-2.obj", 0.14, 0.38, 0.01, center=(0.14, 0.0, 0.0)
    )  # door, hinge at its edge
    write_box_obj(objs / "original-3.obj", 0.12, 0.05, 0.15)  # drawer
    urdf = f"""<?xml version="1.0"?>
<robot name="partnet_{anno_id}">
  <link name="base"/>
  <link name="link_0">
    <visual name="body"><origin xyz="0 0 0"/><geometry><mesh filename="package://textured_objs/original-1.obj"/></geometry></visual>
    <collision><origin xyz="0 0 0"/><geometry><mesh filename="package://textured_objs/original-1.obj"/></geometry></collision>
  </link>
  <link name="link_1">
    <visual><origin xyz="0 0 0"/><geometry><mesh filename="package://textured_objs/original-2.obj"/></geometry></visual>
    <collision><origin xyz="0 0 0"/><geometry><mesh filename="package://textured_objs/original-2.obj"/></geometry></collision>
  </link>
  <link name="link_2">
    <visual><origin xyz="0 0 0"/><geometry><mesh filename="package://textured_objs/original-3.obj"/></geometry></visual>
    <collision><origin xyz="0 0 0"/><geometry><mesh filename="package://textured_objs/original-3.obj"/></geometry></collision>
  </link>
  <joint name="joint_0" type="fixed"><parent link="base"/><child link="link_0"/><origin xyz="0 0 0"/></joint>
  <joint name="joint_1" type="revolute"><parent link="link_0"/><child link="link_1"/>
    <origin xyz="-0.3 0 0.22"/><axis xyz="0 1 0"/><limit lower="0" upper="1.57"/></joint>
  <joint name="joint_2" type="prismatic"><parent link="link_0"/><child link="link_2"/>
    <origin xyz="0.15 0.2 0.05"/><axis xyz="0 0 1"/><limit lower="0" upper="0.2"/></joint>
</robot>
"""
    (folder / "mobility.urdf").write_text(urdf)
    (folder / "meta.json").write_text(
        json.dumps({"model_cat": "StorageFurniture", "anno_id": anno_id, "version": "1"})
    )
    (folder / "semantics.txt").write_text(
        "link_0 static cabinet_frame\nlink_1 hinge door\nlink_2 slider drawer\n"
    )
    return folder


def write_objaverse_item(folder: Path, uid: str = "8f2a9c", name: str = "mug") -> tuple[Path, Path]:
    """One OBJ mesh plus an Objaverse-style annotations.json keyed by uid."""
    obj = write_box_obj(folder / f"{uid}.obj", 0.04, 0.05, 0.04)
    ann = folder / "annotations.json"
    ann.write_text(
        json.dumps(
            {
                uid: {
                    "name": name,
                    "tags": [{"name": "kitchen"}, {"name": "ceramic"}],
                    "categories": [{"name": "food-drink"}],
                    "description": "A plain ceramic coffee mug.",
                }
            }
        )
    )
    return obj, ann
