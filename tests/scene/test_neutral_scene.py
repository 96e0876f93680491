"""The built scene treats every object alike: names, order, sensors, cameras and the robot's start
pose say nothing about which object is the hazard (issue 23, "perception with no hints")."""

from __future__ import annotations

import math

import numpy as np

from anomalygen.config import Settings
from anomalygen.runfolder import read_model
from anomalygen.scene import robot
from anomalygen.scene.graph import FLOOR_GEOM, load_scene
from anomalygen.scene.instances import renumber_by_position
from anomalygen.scene.layout import Layout, Placed
from anomalygen.scene.sensors import sensor_items
from anomalygen.schema import ObjectRole, SceneSpec

OLD_REACH_BAND = (0.35, 0.85)  # m: where the builder used to start the base, facing the hazard


def _box(name: str, x: float, y: float, role=ObjectRole.CLUTTER, *, support: str = "floor") -> Placed:
    p = Placed(name=name, catalogue=name.rsplit("_", 1)[0], role=role, lo=np.array([-0.05, -0.05, 0.0]),
               hi=np.array([0.05, 0.05, 0.1]), fixed=False, support=support)
    p.pos = np.array([x, y, 0.0])
    return p


def test_instances_are_numbered_by_where_they_stand_not_by_role():
    lay = Layout(np.random.default_rng(0))
    table = _box("table_0", 2.0, 0.0, ObjectRole.SUPPORT)
    hazard = _box("kitchen_knife_0", 2.0, 0.5, ObjectRole.HAZARD, support="table_0")
    decoy = _box("kitchen_knife_1", 1.0, 0.5, ObjectRole.CLUTTER, support="table_1")
    side = _box("table_1", 1.0, 0.0)
    placed = {p.name: p for p in (table, hazard, decoy, side)}
    out, bindings = renumber_by_position(lay, placed, {"$hazard": "kitchen_knife_0", "$support": "table_0"})
    assert list(out) == ["kitchen_knife_0", "kitchen_knife_1", "table_0", "table_1"]  # name order
    assert out["kitchen_knife_0"] is decoy and out["kitchen_knife_1"] is hazard  # lower x first
    assert bindings == {"$hazard": "kitchen_knife_1", "$support": "table_1"}
    assert hazard.support == "table_1" and decoy.support == "table_0"  # references follow the renaming


def _facing(base, point) -> bool:
    want = math.atan2(point[1] - base[1], point[0] - base[0])
    return abs((want - base[2] + math.pi) % (2 * math.pi) - math.pi) < 0.6


def test_start_pose_is_free_and_not_set_by_the_hazard(built_scenes):
    near_and_facing = 0
    for key, folder in built_scenes.items():
        model, data, _ = load_scene(folder)
        spec = read_model(folder / "scene.json", SceneSpec)
        base = np.array(spec.robot_base)
        hazard = data.body(spec.bindings["$hazard"]).xpos
        d = float(np.hypot(*(hazard[:2] - base[:2])))
        near_and_facing += OLD_REACH_BAND[0] <= d <= OLD_REACH_BAND[1] and _facing(base, hazard)
        robot_geoms = set(robot.robot_geom_ids(model).tolist())
        floor = model.geom(FLOOR_GEOM).id
        for k in range(data.ncon):  # the robot touches nothing but the floor where it starts
            g1, g2 = int(data.contact.geom1[k]), int(data.contact.geom2[k])
            if (g1 in robot_geoms) != (g2 in robot_geoms):
                assert floor in (g1, g2), (key, model.geom(g1).name, model.geom(g2).name)
    assert near_and_facing <= 1  # the old builder: every scene


def test_start_pose_draw_takes_no_object_as_its_aim():
    """The same layout with the hazard role on another object gives the same start pose."""
    def layout_with(hazard: str) -> Layout:
        lay = Layout(np.random.default_rng(3))
        for name, x in (("mug_0", 1.0), ("pill_bottle_0", 1.8)):
            lay.items.append(_box(name, x, 0.3, ObjectRole.HAZARD if name == hazard else ObjectRole.CLUTTER))
        return lay

    assert np.array_equal(layout_with("mug_0").draw_start_pose(), layout_with("pill_bottle_0").draw_start_pose())


def _in_view(model, data, cam: str, point, aspect: float) -> bool:
    c = model.camera(cam).id
    rel = data.cam_xmat[c].reshape(3, 3).T @ (np.asarray(point) - data.cam_xpos[c])
    depth = -rel[2]  # cameras look along their -z
    tan_v = math.tan(math.radians(model.cam_fovy[c]) / 2)
    return depth > 0 and abs(rel[1]) <= depth * tan_v and abs(rel[0]) <= depth * tan_v * aspect


def test_room_cameras_see_every_object_and_sensors_cover_every_object(built_scenes):
    settings = Settings()
    aspect = settings.build.render_width / settings.build.render_height
    for key, folder in built_scenes.items():
        model, data, _ = load_scene(folder)
        spec = read_model(folder / "scene.json", SceneSpec)
        names = [o.name for o in spec.objects]
        assert names == sorted(names), key  # scene.json (and so the graph) in name order
        assert sensor_items(model, "object_pos") == names, key  # clutter and decoys too
        for name in names:
            center = data.body(name).xpos
            for cam in ("front", "top"):
                assert _in_view(model, data, cam, center, aspect), (key, name, cam)
