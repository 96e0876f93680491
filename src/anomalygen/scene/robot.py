"""The robot at run time: its element names, the :class:`Robot` that resolves them, suction and lift.

A Franka Panda arm with a suction cup, on a mobile base (planar x, y, yaw); the MJCF is built by
:mod:`anomalygen.scene.robot_model`. Why a mobile base: household hazards lie on the floor, on
counters and on shelves across a room; a fixed arm reaches none of that. Three joints (``base_x``,
``base_y`` slide, ``base_yaw`` hinge) move the base on the floor, with position actuators of the same
names. Why a torso lift (body ``torso`` under the arm, as on Fetch, TIAGo or Stretch): with the arm's
shoulder at counter height the cup cannot reach, face-down, the lid of a box that stands on a 0.9 m
counter; raised by up to ``LIFT_MAX`` it can. It rests at 0, where the arm reaches the floor;
``set_lift`` moves it.

Names other stages rely on (see docs/scene.md), each a constant below so no module spells them out:

* joints ``base_x base_y base_yaw panda_joint1 .. panda_joint7`` (``ROBOT_JOINTS``), each with a
  position actuator of the same name (``ctrl`` = target joint value);
* bodies ``base``, ``torso`` (carried by the lift), ``panda_link0 .. panda_link7``, ``suction`` (the cup);
* sites ``ee_site`` (tool frame, z axis pointing out of the cup) and ``suction_site`` (cup face);
* mocap body ``ee_target`` and weld ``ee_track`` (inactive unless an env or the Driver drives the
  arm by end-effector targets);
* welds ``suction__<object>`` from the cup to each free object, all inactive at build time; toggle
  them with :func:`suction_on` / :func:`suction_off`.
* ``set_home``: base joints at the scene's base pose, arm at ``HOME_ARM`` (cup pointing down);
  built scenes store their settled start state as keyframe ``init``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    import mujoco

ARM_JOINTS = tuple(f"panda_joint{i}" for i in range(1, 8))
BASE_JOINTS = ("base_x", "base_y", "base_yaw")
ROBOT_JOINTS = BASE_JOINTS + ARM_JOINTS
# Arm position gains (kp, N m force limit) per joint, from the source actuator.xml.
ARM_GAINS = ((870, 87), (870, 87), (870, 87), (870, 87), (120, 12), (120, 12), (120, 12))
BASE_BODY = "base"
TORSO = "torso"  # the body the lift raises
CUP_BODY = "suction"  # the suction cup at the end of the arm
CUP_GEOM = "suction_geom"
CUP_SITE = "suction_site"  # the cup face: where objects are held, "ee" in reward state dicts
EE_SITE = "ee_site"  # tool frame, z out of the cup
EE_TARGET = "ee_target"  # mocap body the cup follows in end-effector control
EE_TRACK = "ee_track"  # weld from the cup to EE_TARGET
# A tucked arm pose with the cup pointing straight down 0.3 m in front of the base at 1.01 m height
# (found by forward kinematics; tests check it): tucked and above counter height, so the base can
# drive up to tables and counters without the arm hitting them.
HOME_ARM = (0.0, -0.5, 0.0, -1.55, 0.0, -0.55, -0.785)
BASE_HEIGHT = 0.30  # m: top of the mobile base, where the arm's link0 stands with the lift down
LIFT_MAX = 0.30  # m the torso lift raises the arm
BASE_RADIUS = 0.22  # m
SUCTION_RANGE = 0.012  # m: how far from the cup face an object may be and still be grabbed
SUCTION_PREFIX = "suction__"
ROBOT_BODY_PREFIXES = (BASE_BODY, TORSO, "panda_", CUP_BODY, EE_TARGET)
# m: the mocap target never runs further than this ahead of the cup, so the weld never yanks the arm
TARGET_LEASH = 0.08


def set_home(model: mujoco.MjModel, data: mujoco.MjData, base_xyyaw=None) -> None:
    """Put the robot at its home pose (arm) and a base pose; controls hold that pose."""
    for name, value in zip(ARM_JOINTS, HOME_ARM, strict=True):
        data.joint(name).qpos[0] = value
        data.actuator(name).ctrl[0] = value
    if base_xyyaw is not None:
        for name, value in zip(BASE_JOINTS, base_xyyaw, strict=True):
            data.joint(name).qpos[0] = value
    set_lift(model, data, 0.0)
    for name in BASE_JOINTS:
        data.actuator(name).ctrl[0] = data.joint(name).qpos[0]


def lift(model: mujoco.MjModel) -> float:
    """How far the torso lift has raised the arm (metres)."""
    return float(model.body(TORSO).pos[2])


def set_lift(model: mujoco.MjModel, data: mujoco.MjData, value: float) -> float:
    """Raise the arm by ``value`` (clipped to 0..LIFT_MAX) and update the kinematics; returns the value.

    Kinematic, like the primitives' base placement: the lift is set between motions, never while the
    arm pushes on something. It lives in the model, so it applies to every MjData of that model."""
    import mujoco

    value = float(np.clip(value, 0.0, LIFT_MAX))
    model.body(TORSO).pos[2] = value
    mujoco.mj_kinematics(model, data)
    return value


def enable_ee_tracking(model: mujoco.MjModel, data: mujoco.MjData) -> int:
    """Switch to end-effector control: the cup follows mocap body ``ee_target`` through the
    ``ee_track`` weld; arm actuators go limp (zero gains) while the base actuators keep holding the
    base where its ``ctrl`` says. The target starts at the cup's current pose. Returns the mocap id.
    """
    import mujoco

    for name in ARM_JOINTS:
        a = model.actuator(name).id
        model.actuator_gainprm[a, :] = 0.0
        model.actuator_biasprm[a, :] = 0.0
    eq = model.equality(EE_TRACK).id
    model.eq_data[eq, :] = 0.0
    model.eq_data[eq, 6] = 1.0
    model.eq_data[eq, 10] = 1.0
    mocap = int(model.body_mocapid[model.body(EE_TARGET).id])
    mujoco.mj_kinematics(model, data)
    cup = model.body(CUP_BODY).id
    data.mocap_pos[mocap] = data.xpos[cup]
    data.mocap_quat[mocap] = data.xquat[cup]
    for name in BASE_JOINTS:
        data.actuator(name).ctrl[0] = data.joint(name).qpos[0]
    data.eq_active[eq] = 1
    return mocap


def robot_geom_ids(model: mujoco.MjModel) -> np.ndarray:
    """Geoms that belong to the robot (base, arm, cup), for contact filtering."""
    import mujoco

    ids = []
    for g in range(model.ngeom):
        body = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, model.geom_bodyid[g]) or ""
        if body.startswith(ROBOT_BODY_PREFIXES):
            ids.append(g)
    return np.asarray(ids, dtype=int)


def suction_eq(model: mujoco.MjModel, object_body: str) -> int:
    import mujoco

    return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_EQUALITY, SUCTION_PREFIX + object_body)


def suction_candidates(model: mujoco.MjModel) -> list[str]:
    """Object bodies the cup can hold (those with a suction weld)."""
    import mujoco

    out = []
    for e in range(model.neq):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_EQUALITY, e) or ""
        if name.startswith(SUCTION_PREFIX):
            out.append(name[len(SUCTION_PREFIX) :])
    return out


def object_distance_to_cup(model: mujoco.MjModel, data: mujoco.MjData, object_body: str) -> float:
    """Smallest distance between the cup geom and any geom of the object body (negative: overlap)."""
    import mujoco

    cup = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, CUP_GEOM)
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, object_body)
    best = np.inf
    fromto = np.zeros(6)
    for g in np.flatnonzero(subtree_geoms(model, body)):
        d = mujoco.mj_geomDistance(model, data, cup, int(g), 0.1, fromto)
        best = min(best, d)
    return float(best)


def subtree_geoms(model: mujoco.MjModel, body: int) -> np.ndarray:
    """Boolean mask of geoms attached to ``body`` or its descendants."""
    mask = np.zeros(model.ngeom, dtype=bool)
    bodies = {body}
    for b in range(body + 1, model.nbody):
        if model.body_parentid[b] in bodies:
            bodies.add(b)
    for g in range(model.ngeom):
        if model.geom_bodyid[g] in bodies:
            mask[g] = True
    return mask


def held_object(model: mujoco.MjModel, data: mujoco.MjData) -> str | None:
    """The object currently welded to the cup, if any."""
    for name in suction_candidates(model):
        if data.eq_active[suction_eq(model, name)]:
            return name
    return None


def suction_on(model: mujoco.MjModel, data: mujoco.MjData, object_name: str | None = None, *,
               torquescale: float = 1.0) -> bool:
    """Grab ``object_name`` (or the nearest candidate) if it is within SUCTION_RANGE of the cup.

    The weld's relative pose is set to the current one, so the object does not jump. Returns True
    when an object is now held. ``torquescale`` 0 holds the position only: a door or lid held by
    its face may then turn under the cup as it swings.
    """
    import mujoco

    if held_object(model, data) is not None:
        return True
    mujoco.mj_kinematics(model, data)
    names = [object_name] if object_name is not None else suction_candidates(model)
    best, best_d = None, SUCTION_RANGE
    for name in names:
        if suction_eq(model, name) < 0:
            continue
        d = object_distance_to_cup(model, data, name)
        if d <= best_d:
            best, best_d = name, d
    if best is None:
        return False
    eq = suction_eq(model, best)
    cup = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, CUP_BODY)
    obj = int(model.eq_obj2id[eq])  # the body the weld holds (the object's massive body)
    relpos, relquat = relative_pose(data.xpos[cup], data.xquat[cup], data.xpos[obj], data.xquat[obj])
    # Weld data layout: anchor(3) in body2's frame, relpos(3) = where that anchor sits in body1's
    # frame, relquat(4) = orientation of body2 in body1, torquescale(1). A full weld anchors at body2's
    # origin; a position-only hold (torquescale 0) anchors at the cup's centre instead, since a door's
    # frame sits on its hinge, where holding the position would hold nothing.
    anchor = np.zeros(3)
    if torquescale < 1.0:
        anchor = data.xmat[obj].reshape(3, 3).T @ (data.xpos[cup] - data.xpos[obj])
        relpos = np.zeros(3)
    model.eq_data[eq, 0:3] = anchor
    model.eq_data[eq, 3:6] = relpos
    model.eq_data[eq, 6:10] = relquat
    model.eq_data[eq, 10] = torquescale
    data.eq_active[eq] = 1
    return True


def suction_off(model: mujoco.MjModel, data: mujoco.MjData, object_name: str | None = None) -> None:
    """Release the held object (or ``object_name``)."""
    names = [object_name] if object_name is not None else suction_candidates(model)
    for name in names:
        eq = suction_eq(model, name)
        if eq >= 0:
            data.eq_active[eq] = 0


def relative_pose(pos1, quat1, pos2, quat2) -> tuple[np.ndarray, np.ndarray]:
    """Pose of frame 2 expressed in frame 1."""
    import mujoco

    neg = np.zeros(4)
    mujoco.mju_negQuat(neg, quat1)
    relpos = np.zeros(3)
    mujoco.mju_rotVecQuat(relpos, np.asarray(pos2) - np.asarray(pos1), neg)
    relquat = np.zeros(4)
    mujoco.mju_mulQuat(relquat, neg, np.asarray(quat2, dtype=float))
    return relpos, relquat


class Robot:
    """The robot in one compiled model, as ManiSkill's agents are: element ids resolved once, the held
    object, subtree geoms, and the one mapping from a 7-D action to the end-effector target.

    Every env and the Driver go through it, so there is one rotation convention (rotations are
    axis-angle in the cup frame) and one leash (:data:`TARGET_LEASH`).
    """

    def __init__(self, model: mujoco.MjModel):
        import mujoco

        self._mj = mujoco
        self.model = model
        self.cup = int(model.body(CUP_BODY).id)
        self.cup_geom = int(model.geom(CUP_GEOM).id)
        self.cup_site = int(model.site(CUP_SITE).id)
        self.ee_site = int(model.site(EE_SITE).id)
        self.track = int(model.equality(EE_TRACK).id)
        self.mocap = int(model.body_mocapid[model.body(EE_TARGET).id])
        self.geoms = robot_geom_ids(model)
        self.suction_objects = suction_candidates(model)
        self._suction_eqs = np.array([suction_eq(model, n) for n in self.suction_objects], dtype=int)
        self._data = None

    # ------------------------------------------------------------------ state
    def held(self, data: mujoco.MjData) -> str | None:
        """The object welded to the cup, if any (the first active suction weld, as ``held_object``)."""
        if not len(self._suction_eqs):
            return None
        on = np.flatnonzero(data.eq_active[self._suction_eqs])
        return self.suction_objects[int(on[0])] if len(on) else None

    def subtree_geoms(self, body: int | str) -> np.ndarray:
        """Boolean mask of the geoms of ``body`` (id or name) and its descendants."""
        return subtree_geoms(self.model, self.model.body(body).id if isinstance(body, str) else int(body))

    def enable_ee_tracking(self, data: mujoco.MjData) -> int:
        """End-effector control on (see :func:`enable_ee_tracking`); returns the mocap index."""
        return enable_ee_tracking(self.model, data)

    # ------------------------------------------------------------------ control
    def leash(self, data: mujoco.MjData, pos) -> None:
        """Put the end-effector target at ``pos``, but at most TARGET_LEASH from the cup per axis."""
        cup = data.xpos[self.cup]
        data.mocap_pos[self.mocap] = cup + np.clip(np.asarray(pos) - cup, -TARGET_LEASH, TARGET_LEASH)

    def target_towards(self, data: mujoco.MjData, want, max_step: float) -> None:
        """Move the target at most ``max_step`` metres straight towards ``want`` (leashed): the
        primitives' way of following a line, one control step at a time."""
        delta = np.asarray(want) - data.mocap_pos[self.mocap]
        n = np.linalg.norm(delta)
        if n > max_step:
            delta *= max_step / n
        self.leash(data, data.mocap_pos[self.mocap] + delta)

    def move_target(self, data: mujoco.MjData, action, *, dp: float, dr: float) -> None:
        """Move the target by ``dp * a[:3]`` (leashed) and turn it by the axis-angle ``a[3:6]`` (at most
        ``dr`` rad) in the cup frame. ``action`` is a float64 array whose entries lie in [-1, 1].

        The arithmetic is exactly that of the SAC door benchmark's env, so its learning curves (and
        the tests that pin them) are unchanged: the axis is ``a / (|a| + 1e-9)``, and the target
        quaternion is renormalised every step. Scalar maths where it gives numpy's exact values, and
        MuJoCo's own quaternion functions where it would not, keep it cheap: it is every env's hot path.
        """
        if data is not self._data:  # cache the views: each MjData attribute access is a pybind call
            self._data = data
            self._mpos, self._mquat, self._cpos = data.mocap_pos[self.mocap], data.mocap_quat[self.mocap], data.xpos[self.cup]
            self._axis, self._dq, self._q = np.zeros(3), np.zeros(4), np.zeros(4)
        a0, a1, a2, a3, a4, a5 = action.tolist()[:6]
        mx, my, mz = self._mpos.tolist()
        cx, cy, cz = self._cpos.tolist()
        lim = TARGET_LEASH
        # cup + clip(target + dp * a - cup): float for float the same operations as numpy's
        self._mpos[:] = (cx + min(max(mx + dp * a0 - cx, -lim), lim), cy + min(max(my + dp * a1 - cy, -lim), lim),
                         cz + min(max(mz + dp * a2 - cz, -lim), lim))
        r = action[3:6]
        n = math.sqrt(r.dot(r))  # = np.linalg.norm(r); a Python sum of squares rounds differently
        k = n + 1e-9
        self._axis[:] = (a3 / k, a4 / k, a5 / k)
        self._mj.mju_axisAngle2Quat(self._dq, self._axis, dr * min(1.0, n))
        q = self._q
        self._mj.mju_mulQuat(q, self._mquat, self._dq)  # q_target * dq: a turn about the cup's own axes
        w, x, y, z = q.tolist()
        k = math.sqrt(q.dot(q))  # = np.linalg.norm(q)
        self._mquat[:] = (w / k, x / k, y / k, z / k)

    def apply_action(self, data: mujoco.MjData, action, *, dp: float, dr: float) -> np.ndarray:
        """Map one 7-D action onto the target and the suction toggle (no physics step).

        ``a[:6]`` as in :meth:`move_target`; ``a[6] > 0`` grabs the nearest suction candidate within
        SUCTION_RANGE (:meth:`grab_nearest`), ``<= 0`` releases. Returns the clipped action (reward
        action penalties read it).
        """
        a = np.clip(np.asarray(action, dtype=float).reshape(7), -1.0, 1.0)
        self.move_target(data, a, dp=dp, dr=dr)
        if len(self._suction_eqs):
            held = self.held(data)
            if a[6] > 0 and held is None:
                self.grab_nearest(data)
            elif a[6] <= 0 and held is not None:
                suction_off(self.model, data)
        return a

    def grab_nearest(self, data: mujoco.MjData) -> bool:
        """Suction on the nearest candidate within range; a part (door, lid, drawer: a body on a hinge
        or slide) is held by position only (torque scale 0), as the part skills do, so it can turn
        under the cup as it swings; a free object is held rigidly."""
        import mujoco

        m = self.model
        mujoco.mj_kinematics(m, data)
        best, best_d = None, SUCTION_RANGE
        for name in self.suction_objects:
            dist = object_distance_to_cup(m, data, name)
            if dist <= best_d:
                best, best_d = name, dist
        if best is None:
            return False
        j = int(m.body_jntadr[m.body(best).id])
        part = j >= 0 and m.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE
        return suction_on(m, data, best, torquescale=0.0 if part else 1.0)
