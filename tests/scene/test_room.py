"""Rooms that read as rooms: walls behind the objects, windows and doors mounted in them, and a front
view in which the robot covers neither any object nor the object at fault."""

from __future__ import annotations

import numpy as np
import pytest

from anomalygen.scene import viewpoint, walls

from .conftest import make_task

ROOM_TASKS = {
    "window": make_task("t-window", "close_window_near_child", "Window", "Window", "floor",
                        articulations=[("Window", "window", "open")], room="living_room"),
    "door": make_task("t-door", "reduce_tripping_hazards", "Door", "towel", "walkway"),
}


@pytest.fixture(scope="module")
def room_scenes(tmp_path_factory, scene_settings):
    from anomalygen.scene.build import build_scene

    root = tmp_path_factory.mktemp("rooms")
    for key, task in ROOM_TASKS.items():
        build_scene(task, seed=0, settings=scene_settings, out_dir=root / key)
    return {key: root / key for key in ROOM_TASKS}


def _wall_geoms(model) -> np.ndarray:
    return walls.wall_geoms(model)


def _mounted(folder, category):
    from anomalygen.world.graph import load_scene

    model, data, spec = load_scene(folder)
    obj = next(o for o in spec.objects if o.asset.category == category)
    return model, data, spec, obj


@pytest.mark.parametrize("key,category,bottom", [("window", "Window", walls.WINDOW_SILL), ("door", "Door", 0.0)])
def test_windows_and_doors_are_mounted_in_a_wall_at_their_height(room_scenes, key, category, bottom):
    import mujoco

    model, data, _, obj = _mounted(room_scenes[key], category)
    lo, hi = viewpoint.object_aabb(model, data, obj.name)
    assert walls.wall_of(lo, hi) in ("back", "side"), (lo, hi)
    assert lo[2] == pytest.approx(bottom, abs=0.03)  # a sill at 0.82 m; a door on the floor
    # the wall has an opening where the object is: no wall geom crosses its box, at either end of its joint
    own = np.flatnonzero(np.isin(model.geom_bodyid, [b for b in range(model.nbody)
                                                     if model.body(b).name.startswith(obj.name)]))
    wall = _wall_geoms(model)
    for js in obj.joint_states:
        for value in js.range:
            data.joint(js.name).qpos[0] = value
            mujoco.mj_forward(model, data)
            pairs = {(int(c.geom1), int(c.geom2)) for c in data.contact[: data.ncon]}
            assert not any((a in wall and b in own) or (b in wall and a in own) for a, b in pairs), (js.name, value)


def test_walls_are_structure_not_items(room_scenes):
    from anomalygen.world.perception import load_scene_graph
    from anomalygen.world.room import ROOM_CENTER, ROOM_HALF

    # the walls stand where the floor area ended before there were walls: every layout still fits
    assert np.allclose([walls.WALL_X, walls.WALL_Y], ROOM_CENTER + ROOM_HALF + 0.3)

    for folder in room_scenes.values():
        graph = load_scene_graph(folder)
        assert graph.objects and not any("wall" in o.name for o in graph.objects)


def test_walls_fill_the_background_behind_the_objects(room_scenes, built_scenes, scene_settings):
    from anomalygen.mjgeom import FLOOR_GEOM
    from anomalygen.world.graph import load_scene
    from anomalygen.world.render import SceneRenderer

    b = scene_settings.build
    for key, folder in {**room_scenes, **built_scenes}.items():
        model, data, spec = load_scene(folder)
        wall = walls.wall_geoms(model, spec)  # walls, and windows or doors in them
        with SceneRenderer(model, b.render_width, b.render_height) as r:
            seg = r.segment(data, "front")
        assert not np.any(seg < 0), key  # no empty background: floor, walls or things everywhere
        top = seg[:2]
        assert not np.any(top == model.geom(FLOOR_GEOM).id), key  # the top edge: walls, never bare floor beyond
        assert np.isin(seg, wall).mean() > 0.05, key


def test_object_at_fault_is_not_covered_by_the_arm(room_scenes, built_scenes, scene_settings):
    from anomalygen.runfolder import read_model
    from anomalygen.scene.build import at_fault
    from anomalygen.schema import SceneSpec
    from anomalygen.world.graph import load_scene
    from anomalygen.world.render import SceneRenderer

    b = scene_settings.build
    for key, folder in {**room_scenes, **built_scenes}.items():
        spec = read_model(folder / "scene.json", SceneSpec)
        recorded = {c.name: c for c in spec.validation.checks}
        assert recorded["render_unobstructed:front"].passed, (key, recorded["render_unobstructed:front"].detail)
        model, data, _ = load_scene(folder)  # measured again from the written files
        with SceneRenderer(model, b.render_width, b.render_height) as r:
            check = viewpoint.fault_coverage(r, model, data, at_fault(spec.bindings), cameras=("front",))[0]
        assert check.passed and check.value <= viewpoint.COVER_MAX, (key, check.detail)
        assert check.value == pytest.approx(recorded["render_unobstructed:front"].value, abs=0.02)


def test_front_view_moves_away_from_a_robot_in_the_way(built_scenes, scene_settings):
    """A candidate view looking over the robot's shoulder at the fridge is passed over for the next one."""
    import mujoco

    from anomalygen.world.graph import load_scene
    from anomalygen.world.render import SceneRenderer

    folder = built_scenes["fridge"]
    model, data, spec = load_scene(folder)
    mjspec = mujoco.MjSpec.from_file(str(folder / "scene.xml"))
    fridge = next(o for o in spec.objects if o.asset.category == "Refrigerator")
    target = np.asarray(data.body(fridge.name).xpos) + [0, 0, 0.7]
    base = np.r_[spec.robot_base[:2], 0.0]
    away = (base - target) * [1, 1, 0]
    eye = base + away / np.linalg.norm(away) * 0.7 + [0, 0, 1.0]
    blocked = (eye, viewpoint.look_at_xyaxes(eye, target))
    mat = np.zeros(9)
    mujoco.mju_quat2Mat(mat, model.cam_quat[model.camera("front").id])
    clear = (model.camera("front").pos.copy(), [*mat.reshape(3, 3)[:, 0], *mat.reshape(3, 3)[:, 1]])
    b = scene_settings.build
    with SceneRenderer(model, b.render_width, b.render_height) as r:
        view, worst = viewpoint.choose_front_view(r, model, data, mjspec, [o.name for o in spec.objects], [blocked, clear])
    assert view == 1 and worst <= viewpoint.COVER_MAX
    assert np.allclose(model.camera("front").pos, clear[0])


def test_higher_views_are_candidates_only_when_they_still_look_at_a_wall():
    near = [(np.array([1.8, 1.2, 0.0]), np.array([2.6, 1.8, 1.0]))]  # furniture by the walls' corner
    far = [(np.array([-0.8, -1.9, 0.0]), np.array([-0.2, -1.2, 1.0]))]  # a corner far from both walls
    assert len(viewpoint.front_views(near, 4 / 3)) == len(viewpoint.VIEWS)
    assert len(viewpoint.front_views(far, 4 / 3)) < len(viewpoint.VIEWS)


def test_covered_share_and_box_projection():
    with_robot = np.array([[1, 1, 7], [1, 2, 2]])
    without = np.array([[1, 1, 1], [1, 2, 2]])
    n, share = viewpoint.covered(with_robot, without, np.array([1]), np.array([7]))
    assert n == 4 and share == pytest.approx(0.25)
    assert viewpoint.covered(with_robot, without, np.array([1]), np.array([7]), rect=(0, 0, 2, 2))[1] == 0.0
