"""Where the front camera stands: framed on the furnished room, chosen so the robot hides no object.

The candidate views all look in from the room's open corner at the walls (``VIEWS``: direction from the
room's middle and pitch), each pulled back just far enough to frame every object's footprint up to
``FRAME_TOP``. After settling, ``choose_front_view`` renders a segmentation image of each candidate with
and without the robot and keeps the first view in which no object has more than ``COVER_MAX`` of its
silhouette behind the robot (else the view where the worst-covered object is covered least). Every
object counts alike, so the choice says nothing about which one is the hazard: the robot side reads
these renders. ``fault_coverage`` then measures the object at fault itself, on the builder's side
only (it knows the answer key), for the validation report.
"""

from __future__ import annotations

import math

import numpy as np

from anomalygen.schema import ValidationCheck

CAMERA_FOVY = 55.0  # degrees, both room cameras
FRAME_MARGIN = 0.1  # m of floor kept around the objects' footprints in the room cameras
FRAME_TOP = 1.0  # m: the room cameras see the furnished floor whole up to this height (table and counter tops)
FOCUS_HEIGHT = 0.4  # m: the cameras aim at this height above the middle of the furnished floor
# (horizontal direction from the room's middle to the camera, pitch down in degrees); the first is the
# view scenes always had; the others look from higher or further round, still at the two walls
VIEWS = (((-1.0, -0.7), 45.0), ((-1.0, -0.7), 62.0), ((-0.45, -1.0), 52.0), ((-1.0, -0.15), 52.0),
         ((-1.0, -0.7), 78.0))
COVER_MAX = 0.15  # an object with more of its visible silhouette than this behind the robot is covered
MIN_PIXELS = 12  # an object showing fewer pixels than this (shut in a cupboard) is not judged in a view
TOP_EDGE_RAYS = 65  # rays tested along the top edge of a candidate view (every 5 px at 320 px wide)
HIDDEN_GROUP = 5  # geom group used to hide the robot in the second segmentation render


def look_at_xyaxes(eye, target) -> list[float]:
    """Camera xyaxes (MuJoCo cameras look along -z) for a camera at ``eye`` looking at ``target``."""
    fwd = np.asarray(target, float) - np.asarray(eye, float)
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, [0.0, 0.0, 1.0])
    if np.linalg.norm(right) < 1e-6:
        right = np.array([0.0, -1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    return [*right.tolist(), *up.tolist()]


def frame_box(boxes) -> tuple[np.ndarray, np.ndarray]:
    """The furnished floor: the xy box round every footprint (each object alike), with a margin."""
    lo = np.min([b[0][:2] for b in boxes], axis=0) - FRAME_MARGIN
    hi = np.max([b[1][:2] for b in boxes], axis=0) + FRAME_MARGIN
    return lo, hi


def framed_view(lo, hi, aspect: float, away, pitch_deg: float) -> tuple[np.ndarray, list[float]]:
    """(eye, xyaxes) of a camera looking from horizontal direction ``away`` pitched down ``pitch_deg``,
    just far enough back that the box ``lo``..``hi`` (up to ``FRAME_TOP``) fits its view."""
    focus = np.r_[(lo + hi) / 2, FOCUS_HEIGHT]
    tan_v = math.tan(math.radians(CAMERA_FOVY) / 2)
    tan_h = tan_v * aspect
    away = np.asarray(away, float) / np.linalg.norm(away)
    pitch = math.radians(pitch_deg)
    fwd = -np.r_[away * math.cos(pitch), math.sin(pitch)]
    right = np.cross(fwd, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (0.0, FRAME_TOP)]) - focus
    # a point stays in view when its sideways and upward offsets fit the view's half-angles at its
    # depth; the depth grows one for one as the eye moves back along the viewing direction
    depth = corners @ fwd
    back = max(float(np.max(np.abs(corners @ right) / tan_h - depth)), float(np.max(np.abs(corners @ up) / tan_v - depth)))
    eye = focus - fwd * back
    return eye, look_at_xyaxes(eye, focus)


def front_views(boxes, aspect: float) -> list[tuple[np.ndarray, list[float]]]:
    """The candidate views of a scene, in order: the first always, the others only when the top of
    their image meets a wall before the floor (a view from high above a furnished area far from the
    walls would show bare floor behind the objects)."""
    lo, hi = frame_box(boxes)
    views = [framed_view(lo, hi, aspect, away, pitch) for away, pitch in VIEWS]
    return views[:1] + [v for v in views[1:] if top_edge_meets_wall(*v, aspect)]


def top_edge_meets_wall(eye, xyaxes, aspect: float) -> bool:
    """Do the rays through the top edge of a view (``TOP_EDGE_RAYS`` of them, corners included) hit a
    wall before the floor? The walls' corner is the farthest point: a view may see floor just there."""
    from anomalygen.scene.walls import WALL_X, WALL_Y

    x, y = np.asarray(xyaxes[:3]), np.asarray(xyaxes[3:])
    tan_v = math.tan(math.radians(CAMERA_FOVY) / 2)
    for side in np.linspace(-1.0, 1.0, TOP_EDGE_RAYS):
        d = -np.cross(x, y) + tan_v * y + side * tan_v * aspect * x
        floor = -eye[2] / d[2] if d[2] < 0 else math.inf
        wall = min((WALL_X - eye[0]) / d[0] if d[0] > 0 else math.inf, (WALL_Y - eye[1]) / d[1] if d[1] > 0 else math.inf)
        if wall >= floor:
            return False
    return True


def _set_camera(model, mjspec, name: str, eye, xyaxes) -> None:
    """Point the compiled model's camera and the spec's (for scene.xml) at the same view."""
    import mujoco

    x, y = np.asarray(xyaxes[:3]), np.asarray(xyaxes[3:])
    mat = np.column_stack([x, y, np.cross(x, y)])
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, mat.flatten())
    cid = model.camera(name).id
    model.cam_pos[cid], model.cam_quat[cid] = eye, quat
    cam = mjspec.camera(name)
    cam.pos = list(map(float, eye))
    cam.alt.type = mujoco.mjtOrientation.mjORIENTATION_XYAXES
    cam.alt.xyaxes = list(map(float, xyaxes))


def _two_segmentations(renderer, model, data, camera: str) -> tuple[np.ndarray, np.ndarray]:
    """Geom ids per pixel with the robot, and with the robot hidden."""
    import mujoco

    from anomalygen.robot.agent import Agent

    mujoco.mj_kinematics(model, data)
    mujoco.mj_camlight(model, data)
    with_robot = renderer.segment(data, camera)
    robot = Agent.geom_ids(model)
    groups = model.geom_group[robot].copy()
    model.geom_group[robot] = HIDDEN_GROUP
    try:
        without = renderer.segment(data, camera, hide_group=HIDDEN_GROUP)
    finally:
        model.geom_group[robot] = groups
    return with_robot, without


def _object_geoms(model, name: str) -> np.ndarray:
    from anomalygen.robot.frames import subtree_geoms

    return np.flatnonzero(subtree_geoms(model, model.body(name).id))


def covered(with_robot, without, geoms, robot, rect=None) -> tuple[int, float]:
    """(pixels the object shows with the robot hidden, share of them the robot covers), inside
    ``rect`` (u0, v0, u1, v1: its projected bounding box) when given."""
    if rect is not None:
        u0, v0, u1, v1 = rect
        with_robot, without = with_robot[v0:v1, u0:u1], without[v0:v1, u0:u1]
    own = np.isin(without, geoms)
    n = int(own.sum())
    if n == 0:
        return 0, 0.0
    return n, float(np.isin(with_robot[own], robot).sum()) / n


def choose_front_view(renderer, model, data, mjspec, names: list[str], views) -> tuple[int, float]:
    """Set the ``front`` camera to the first candidate view where no object is covered by the robot
    (the least-covered view when none is clear); returns (view index, worst object's covered share)."""
    from anomalygen.robot.agent import Agent

    robot = Agent.geom_ids(model)
    geoms = [_object_geoms(model, n) for n in names]
    best, best_worst = 0, math.inf
    for i, (eye, xyaxes) in enumerate(views):
        _set_camera(model, mjspec, "front", eye, xyaxes)
        with_robot, without = _two_segmentations(renderer, model, data, "front")
        shares = [s for n, s in (covered(with_robot, without, g, robot) for g in geoms) if n >= MIN_PIXELS]
        worst = max(shares, default=0.0)
        if worst < best_worst - 1e-9:
            best, best_worst = i, worst
        if worst <= COVER_MAX:
            break
    import mujoco

    _set_camera(model, mjspec, "front", *views[best])
    mujoco.mj_kinematics(model, data)
    mujoco.mj_camlight(model, data)
    return best, best_worst


def project_box(model, data, camera: str, lo, hi, width: int, height: int) -> tuple[int, int, int, int] | None:
    """Pixel rectangle (u0, v0, u1, v1) of a world AABB seen by a fixed camera; None when behind it."""
    cid = model.camera(camera).id
    pos, rot = data.cam_xpos[cid], data.cam_xmat[cid].reshape(3, 3)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    local = (corners - pos) @ rot  # camera frame: x right, y up, looking along -z
    if np.any(local[:, 2] >= -1e-6):
        return None
    f = (height / 2) / math.tan(math.radians(model.cam_fovy[cid]) / 2)
    u = width / 2 + f * local[:, 0] / -local[:, 2]
    v = height / 2 - f * local[:, 1] / -local[:, 2]
    u0, u1 = int(np.clip(np.floor(u.min()), 0, width)), int(np.clip(np.ceil(u.max()), 0, width))
    v0, v1 = int(np.clip(np.floor(v.min()), 0, height)), int(np.clip(np.ceil(v.max()), 0, height))
    return (u0, v0, u1, v1) if u1 > u0 and v1 > v0 else None


def object_aabb(model, data, name: str) -> tuple[np.ndarray, np.ndarray]:
    """World AABB of an object's geoms (each geom's box turned into the world)."""
    los, his = [], []
    for g in _object_geoms(model, name):
        center, half = model.geom_aabb[g][:3], model.geom_aabb[g][3:]
        rot = data.geom_xmat[g].reshape(3, 3)
        c = data.geom_xpos[g] + rot @ center
        h = np.abs(rot) @ half
        los.append(c - h)
        his.append(c + h)
    return np.min(los, axis=0), np.max(his, axis=0)


def fault_coverage(renderer, model, data, name: str, cameras=("front", "top")) -> list[ValidationCheck]:
    """Per render camera: is the object at fault (``name``) in view and not covered by the robot?

    Its bounding box is projected into the camera; inside that rectangle, the pixels the object
    shows with the robot hidden are compared with the same pixels with the robot drawn."""
    from anomalygen.robot.agent import Agent

    robot = Agent.geom_ids(model)
    geoms = _object_geoms(model, name)
    lo, hi = object_aabb(model, data, name)
    out = []
    for cam in cameras:
        with_robot, without = _two_segmentations(renderer, model, data, cam)
        rect = project_box(model, data, cam, lo, hi, renderer.width, renderer.height)
        n, share = covered(with_robot, without, geoms, robot, rect) if rect is not None else (0, 0.0)
        if rect is None:
            detail = f"{name}'s bounding box is out of the {cam} view"
        elif n == 0:
            detail = f"{name} shows no pixels in the {cam} view (hidden by furniture, not by the robot)"
        else:
            detail = f"{name} shows {n} px in the {cam} view; the robot covers {share:.0%} of them"
        out.append(ValidationCheck(name=f"render_unobstructed:{cam}", passed=rect is not None and share <= COVER_MAX,
                                   value=round(share, 4), detail=detail))
    return out
