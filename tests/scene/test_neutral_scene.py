"""The built scene treats every object alike: names, order, sensors, cameras and the robot's start
pose (its dock) say nothing about which object is the hazard (issue 23, "perception with no hints")."""

from __future__ import annotations

import math

import numpy as np

from anomalygen.config import Settings
from anomalygen.mjgeom import FLOOR_GEOM
from anomalygen.rng import item_rng
from anomalygen.robot.agent import Agent
from anomalygen.runfolder import read_model
from anomalygen.scene import build
from anomalygen.scene.instances import renumber_by_position
from anomalygen.scene.layout import DOCK_YAW, Layout, Placed
from anomalygen.schema import ObjectRole, SceneSpec
from anomalygen.world.graph import load_scene
from anomalygen.world.sensors import sensor_items

from .conftest import TASKS

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


def test_robot_starts_docked_the_same_in_every_scene_touching_nothing(built_scenes):
    for key, folder in built_scenes.items():
        model, data, _ = load_scene(folder)
        spec = read_model(folder / "scene.json", SceneSpec)
        base = np.array(spec.robot_base)
        # the dock (not where the hazard is), turned along the front unless the arm would touch
        # something there (a real cabinet's door room, say): then facing into the room (Layout.dock_pose)
        assert any(np.allclose(base, [0.0, 0.0, yaw]) for yaw in (DOCK_YAW, 0.0)), key
        hazard = data.body(spec.bindings["$hazard"]).xpos
        d = float(np.hypot(*(hazard[:2] - base[:2])))
        assert not (OLD_REACH_BAND[0] <= d <= OLD_REACH_BAND[1] and _facing(base, hazard)), key
        robot_geoms = set(Agent.geom_ids(model).tolist())
        floor = model.geom(FLOOR_GEOM).id
        for k in range(data.ncon):  # the robot touches nothing but the floor where it starts
            g1, g2 = int(data.contact.geom1[k]), int(data.contact.geom2[k])
            if (g1 in robot_geoms) != (g2 in robot_geoms):
                assert floor in (g1, g2), (key, model.geom(g1).name, model.geom(g2).name)


def test_reach_start_is_the_answer_key_pose_only_when_asked_for():
    task = TASKS["floor"]
    poses = {}
    for start in ("dock", "reach"):
        lay, bindings, placed = build._plan(task, Settings(build={"clutter": 1, "start": start}),
                                            item_rng(0, task.id, 0))
        poses[start] = lay.base
        hazard = placed[bindings["$hazard"]].world_center()
    assert np.array_equal(poses["dock"], [0.0, 0.0, DOCK_YAW])
    d = float(np.hypot(*(hazard[:2] - poses["reach"][:2])))
    assert OLD_REACH_BAND[0] <= d <= OLD_REACH_BAND[1] and _facing(poses["reach"], hazard)


def test_dock_takes_no_object_as_its_aim_and_turns_into_the_room_only_when_blocked():
    def layout_with(hazard: str, blocker: bool = False) -> Layout:
        lay = Layout(np.random.default_rng(3))
        for name, x in (("mug_0", 1.0), ("pill_bottle_0", 1.8)):
            lay.items.append(_box(name, x, 0.3, ObjectRole.HAZARD if name == hazard else ObjectRole.CLUTTER))
        if blocker:  # a tall thing where the arm would hang when turned along the front
            shelf = _box("shelf_0", 0.0, 0.45)
            shelf.lo, shelf.hi = np.array([-0.1, -0.05, 0.0]), np.array([0.1, 0.05, 1.2])
            lay.items.append(shelf)
        return lay

    assert np.array_equal(layout_with("mug_0").dock_pose(), [0.0, 0.0, DOCK_YAW])
    assert np.array_equal(layout_with("pill_bottle_0").dock_pose(), [0.0, 0.0, DOCK_YAW])
    blocked = layout_with("mug_0", blocker=True)
    assert np.array_equal(blocked.dock_pose(), [0.0, 0.0, 0.0])
    assert blocked._pose_free(np.zeros(2), 0.0, swing=True)  # facing into the room, the arm clears it


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


def _room_cameras(objects: list[Placed]) -> dict[str, np.ndarray]:
    import mujoco

    from anomalygen.scene.compose import add_room_cameras

    spec = mujoco.MjSpec()
    add_room_cameras(spec, objects, aspect=4 / 3)
    model = spec.compile()
    return {name: np.r_[model.camera(name).pos, model.camera(name).quat] for name in ("front", "top")}


def test_room_cameras_aim_at_every_object_alike_never_at_the_hazard():
    """Which object is the hazard never moves a camera; where any object stands does."""
    spots = [(0.6, 0.4), (1.8, 0.5), (1.2, 1.9)]
    as_hazard = [_box(f"thing_{k}", x, y, ObjectRole.HAZARD if k == 0 else ObjectRole.CLUTTER)
                 for k, (x, y) in enumerate(spots)]
    as_clutter = [_box(f"thing_{k}", x, y, ObjectRole.HAZARD if k == 2 else ObjectRole.CLUTTER)
                  for k, (x, y) in enumerate(spots)]
    first, second = _room_cameras(as_hazard), _room_cameras(as_clutter)
    for cam in ("front", "top"):
        assert np.allclose(first[cam], second[cam]), cam
    # the top camera stands over the middle of all the footprints, not over the hazard at (0.6, 0.4)
    assert np.allclose(first["top"][:2], [1.2, 1.15], atol=0.02)
    moved = _room_cameras([_box("thing_0", 0.6, 0.4), _box("thing_1", 1.8, 0.5), _box("thing_2", 2.4, 2.4)])
    assert not np.allclose(moved["top"], first["top"])  # a clutter object that moves moves the frame
