"""The robot as one agent class, as ManiSkill's ``BaseAgent`` subclasses are: :class:`Agent`.

A Franka Panda arm with a suction cup, on a mobile base (planar x, y, yaw) with a torso lift. Why a
mobile base: household hazards lie on the floor, on counters and on shelves across a room; a fixed
arm reaches none of that. Why a torso lift (body ``torso`` under the arm, as on Fetch, TIAGo or
Stretch): with the arm's shoulder at counter height the cup cannot reach, face-down, the lid of a box
on a 0.9 m counter; raised by up to ``LIFT_MAX`` it can. It rests at 0, where the arm reaches the
floor.

The class owns everything that names or drives a robot part, so no other module spells one out:

* the model: :meth:`Agent.build_spec` (the MJCF, built by :mod:`anomalygen.robot.model`) and
  :meth:`Agent.add_suction_welds`;
* element names (class constants): joints ``ROBOT_JOINTS`` (``base_x base_y base_yaw`` and
  ``panda_joint1..7``, each with a position actuator of the same name), bodies ``base``, ``torso``,
  ``panda_link0..7``, ``suction`` (the cup), sites ``ee_site`` and ``suction_site``, the mocap body
  ``ee_target`` and its weld ``ee_track``, and one weld ``suction__<object>`` per graspable body;
* the control modes (:meth:`Agent.set_control_mode`): ``"ee_delta_pose"`` (the cup follows the mocap
  target through the ``ee_track`` weld, arm servos limp, base servos hold) and ``"arm_joint_pos"``
  (the arm's position servos with their compiled gains, weld off);
* the grab rule (:meth:`Agent.grab`, :meth:`Agent.release`), the reach envelope (``REACH``,
  :mod:`anomalygen.robot.reach`), and the action mapping with one step size (:meth:`Agent.apply_action`).

An instance resolves the names in one compiled model; built scenes store their settled start as
keyframe ``init``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, ClassVar

import numpy as np

from anomalygen.robot.frames import relative_pose, subtree_geoms
from anomalygen.robot.reach import REACH, Reach

if TYPE_CHECKING:  # pragma: no cover
    import mujoco

CONTROL_MODES = ("ee_delta_pose", "arm_joint_pos")


class Agent:
    """The robot in one compiled model: element ids resolved once, control modes, grab rule, actions."""

    # ---------------------------------------------------------------- element names
    ARM_JOINTS: ClassVar[tuple[str, ...]] = tuple(f"panda_joint{i}" for i in range(1, 8))
    BASE_JOINTS: ClassVar[tuple[str, ...]] = ("base_x", "base_y", "base_yaw")
    ROBOT_JOINTS: ClassVar[tuple[str, ...]] = BASE_JOINTS + ARM_JOINTS
    ARM_LINK_PREFIX: ClassVar[str] = "panda_"  # the arm's bodies: panda_link0 .. panda_link7
    BASE_BODY: ClassVar[str] = "base"
    TORSO: ClassVar[str] = "torso"  # the body the lift raises
    CUP_BODY: ClassVar[str] = "suction"  # the suction cup at the end of the arm
    CUP_GEOM: ClassVar[str] = "suction_geom"
    CUP_SITE: ClassVar[str] = "suction_site"  # the cup face: where objects are held, "ee" in reward state dicts
    EE_SITE: ClassVar[str] = "ee_site"  # tool frame, z out of the cup
    EE_TARGET: ClassVar[str] = "ee_target"  # mocap body the cup follows in end-effector control
    EE_TRACK: ClassVar[str] = "ee_track"  # weld from the cup to EE_TARGET
    WRIST_CAMERA: ClassVar[str] = "wrist"
    SUCTION_PREFIX: ClassVar[str] = "suction__"  # + object body: the weld that holds it
    BODY_PREFIXES: ClassVar[tuple[str, ...]] = (BASE_BODY, TORSO, ARM_LINK_PREFIX, CUP_BODY, EE_TARGET)

    # ---------------------------------------------------------------- dimensions and tuning
    # Arm position gains (kp, N m force limit) per joint, from the source actuator.xml.
    ARM_GAINS: ClassVar[tuple[tuple[int, int], ...]] = (
        (870, 87), (870, 87), (870, 87), (870, 87), (120, 12), (120, 12), (120, 12))
    # A tucked arm pose with the cup pointing straight down 0.3 m in front of the base at 1.01 m height
    # (found by forward kinematics; tests check it): tucked and above counter height, so the base can
    # drive up to tables and counters without the arm hitting them.
    HOME_ARM: ClassVar[tuple[float, ...]] = (0.0, -0.5, 0.0, -1.55, 0.0, -0.55, -0.785)
    BASE_HEIGHT: ClassVar[float] = 0.30  # m: top of the mobile base, where link0 stands with the lift down
    LIFT_MAX: ClassVar[float] = 0.30  # m the torso lift raises the arm
    BASE_RADIUS: ClassVar[float] = 0.22  # m
    # The space the arm takes at HOME_ARM with the lift down, as boxes in the base frame (x forward,
    # y left, z up from the floor; (lo, hi) in metres per axis): the column above the base, and the
    # forearm with the cup, which hangs 0.3 m forward with its lowest point at ~1.01 m (above counters).
    # The scene builder keeps every object out of them (``scene/layout.py::Layout.arm_boxes``).
    HOME_ARM_BOXES: ClassVar[tuple[tuple[tuple[float, float], ...], ...]] = (
        ((-0.2, 0.12), (-0.15, 0.15), (0.3, 1.35)),
        ((0.12, 0.42), (-0.15, 0.15), (0.98, 1.35)),
    )
    # m: suction takes hold of a body whose nearest geom is at most this far from the cup geom
    SUCTION_RANGE: ClassVar[float] = 0.012
    # m: the mocap target never runs further than this ahead of the cup, so the weld never yanks the arm
    TARGET_LEASH: ClassVar[float] = 0.08
    # The action's step size, for every env, the SAC replays and outside policies: the paper's 7-D
    # action moves the cup target by at most STEP_POS metres and turns it by at most STEP_ROT rad.
    STEP_POS: ClassVar[float] = 0.03
    STEP_ROT: ClassVar[float] = 0.1
    REACH: ClassVar[Reach] = REACH

    # ---------------------------------------------------------------- the model
    @classmethod
    def build_spec(cls, base_xyyaw=(0.0, 0.0, 0.0)) -> mujoco.MjSpec:
        """A fresh MjSpec holding only the robot; scenes are built on top of it (see robot/model.py)."""
        from anomalygen.robot.model import build_spec

        return build_spec(cls, base_xyyaw)

    @classmethod
    def add_suction_welds(cls, spec: mujoco.MjSpec, object_bodies: list[str],
                          held_bodies: list[str] | None = None) -> None:
        """One inactive weld per graspable body, so suction is a toggle at run time (robot/model.py)."""
        from anomalygen.robot.model import add_suction_welds

        add_suction_welds(cls, spec, object_bodies, held_bodies)

    @classmethod
    def mesh_files(cls) -> tuple[Path, list[Path]]:
        """The folder of the robot's mesh files and the files the model uses, relative to it."""
        from anomalygen.robot.model import franka_assets_dir, mesh_files

        return franka_assets_dir() / "meshes", mesh_files(cls)

    @classmethod
    def geom_ids(cls, model: mujoco.MjModel) -> np.ndarray:
        """Geoms that belong to the robot (base, torso, arm, cup), for contact filtering."""
        import mujoco

        ids = []
        for g in range(model.ngeom):
            body = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, model.geom_bodyid[g]) or ""
            if body.startswith(cls.BODY_PREFIXES):
                ids.append(g)
        return np.asarray(ids, dtype=int)

    @classmethod
    def graspable(cls, model: mujoco.MjModel) -> list[str]:
        """Bodies the cup can hold (those with a suction weld), in weld order."""
        import mujoco

        out = []
        for e in range(model.neq):
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_EQUALITY, e) or ""
            if name.startswith(cls.SUCTION_PREFIX):
                out.append(name[len(cls.SUCTION_PREFIX):])
        return out

    # ---------------------------------------------------------------- one compiled model
    def __init__(self, model: mujoco.MjModel):
        import mujoco

        self._mj, self._mul_quat = mujoco, mujoco.mju_mulQuat
        self.model = model
        self.cup = int(model.body(self.CUP_BODY).id)
        self.cup_geom = int(model.geom(self.CUP_GEOM).id)
        self.cup_site = int(model.site(self.CUP_SITE).id)
        self.ee_site = int(model.site(self.EE_SITE).id)
        self.track = int(model.equality(self.EE_TRACK).id)
        self.mocap = int(model.body_mocapid[model.body(self.EE_TARGET).id])
        self.geoms = self.geom_ids(model)
        self.suction_objects = self.graspable(model)
        self._suction_eqs = np.array([self.suction_eq(n) for n in self.suction_objects], dtype=int)
        self._eq_list = self._suction_eqs.tolist()
        self._data = None

    def suction_eq(self, body: str) -> int:
        """Id of the suction weld of ``body`` (-1 when it has none)."""
        mj = self._mj
        return mj.mj_name2id(self.model, mj.mjtObj.mjOBJ_EQUALITY, self.SUCTION_PREFIX + body)

    def subtree_geoms(self, body: int | str) -> np.ndarray:
        """Boolean mask of the geoms of ``body`` (id or name) and its descendants."""
        return subtree_geoms(self.model, self.model.body(body).id if isinstance(body, str) else int(body))

    # ---------------------------------------------------------------- pose
    def set_home(self, data: mujoco.MjData, base_xyyaw=None) -> None:
        """Arm at ``HOME_ARM``, base at ``base_xyyaw`` (if given), lift down; the servos hold that pose."""
        for name, value in zip(self.ARM_JOINTS, self.HOME_ARM, strict=True):
            data.joint(name).qpos[0] = value
            data.actuator(name).ctrl[0] = value
        if base_xyyaw is not None:
            for name, value in zip(self.BASE_JOINTS, base_xyyaw, strict=True):
                data.joint(name).qpos[0] = value
        self.set_lift(data, 0.0)
        for name in self.BASE_JOINTS:
            data.actuator(name).ctrl[0] = data.joint(name).qpos[0]

    def base_pose(self, data: mujoco.MjData) -> np.ndarray:
        """(x, y, yaw) of the base, read from its joints."""
        return np.array([data.joint(j).qpos[0] for j in self.BASE_JOINTS])

    def lift(self) -> float:
        """How far the torso lift has raised the arm (metres)."""
        return float(self.model.body(self.TORSO).pos[2])

    def set_lift(self, data: mujoco.MjData, value: float) -> float:
        """Raise the arm by ``value`` (clipped to 0..LIFT_MAX) and update the kinematics; returns the value.

        Kinematic, like the Driver's base placement: the lift is set between motions, never while the
        arm pushes on something. It lives in the model, so it applies to every MjData of that model."""
        value = float(np.clip(value, 0.0, self.LIFT_MAX))
        self.model.body(self.TORSO).pos[2] = value
        self._mj.mj_kinematics(self.model, data)
        return value

    # ---------------------------------------------------------------- control modes
    def set_control_mode(self, data: mujoco.MjData, mode: str) -> None:
        """Switch how the arm is driven (``CONTROL_MODES``); the base servos hold the base either way.

        ``"ee_delta_pose"``: arm actuators limp (zero gains), the cup follows mocap body ``ee_target``
        through the ``ee_track`` weld, the target starting at the cup's current pose and the base
        servos aimed where the base stands. ``"arm_joint_pos"``: the arm's position actuators get back
        the gains the model was compiled with (``set_to_position(kp)``: gain ``kp``, bias ``(0, -kp,
        0)``) and aim at the arm's current joint values, the weld is off. Suction welds are separate
        constraints: a held object stays held across a switch.
        """
        if mode == "ee_delta_pose":
            self._track_ee(data)
        elif mode == "arm_joint_pos":
            m = self.model
            for name, (kp, _) in zip(self.ARM_JOINTS, self.ARM_GAINS, strict=True):
                data.actuator(name).ctrl[0] = data.joint(name).qpos[0]
                a = m.actuator(name).id
                m.actuator_gainprm[a, :] = 0.0
                m.actuator_biasprm[a, :] = 0.0
                m.actuator_gainprm[a, 0] = kp
                m.actuator_biasprm[a, 1] = -kp
            data.eq_active[self.track] = 0
        else:
            raise ValueError(f"unknown control mode {mode!r}; the robot has {', '.join(CONTROL_MODES)}")

    def _track_ee(self, data: mujoco.MjData) -> None:
        mj, m = self._mj, self.model
        for name in self.ARM_JOINTS:
            a = m.actuator(name).id
            m.actuator_gainprm[a, :] = 0.0
            m.actuator_biasprm[a, :] = 0.0
        eq = self.track
        m.eq_data[eq, :] = 0.0
        m.eq_data[eq, 6] = 1.0
        m.eq_data[eq, 10] = 1.0
        mj.mj_kinematics(m, data)
        data.mocap_pos[self.mocap] = data.xpos[self.cup]
        data.mocap_quat[self.mocap] = data.xquat[self.cup]
        for name in self.BASE_JOINTS:
            data.actuator(name).ctrl[0] = data.joint(name).qpos[0]
        data.eq_active[eq] = 1

    # ---------------------------------------------------------------- grab and release
    def held(self, data: mujoco.MjData) -> str | None:
        """The body welded to the cup, if any (the first active suction weld)."""
        active = self._active if data is self._data else data.eq_active
        for k, eq in enumerate(self._eq_list):
            if active[eq]:
                return self.suction_objects[k]
        return None

    def cup_distance(self, data: mujoco.MjData, body: str) -> float:
        """Smallest distance between the cup geom and any geom of ``body``'s subtree (negative: overlap)."""
        mj, m = self._mj, self.model
        b = mj.mj_name2id(m, mj.mjtObj.mjOBJ_BODY, body)
        best = np.inf
        fromto = np.zeros(6)
        for g in np.flatnonzero(subtree_geoms(m, b)):
            d = mj.mj_geomDistance(m, data, self.cup_geom, int(g), 0.1, fromto)
            best = min(best, d)
        return float(best)

    def grab(self, data: mujoco.MjData, body: str | None = None) -> bool:
        """Suction on: the one grab rule of every skill, env and replay. True when something is held.

        The rule: the cup takes hold of ``body`` (or, without one, of the nearest graspable body) when
        its nearest geom lies within ``SUCTION_RANGE`` of the cup geom (``mj_geomDistance`` on the
        current kinematics; touching is not needed). Already holding something counts as held. A free
        body is held rigidly; a part (a body on a hinge or slide: a door, lid, drawer, knob) by position
        only (torque scale 0), anchored at the cup's centre, so it can turn under the cup as it swings.
        The weld starts at the current relative pose, so nothing jumps.
        """
        mj, m = self._mj, self.model
        if self.held(data) is not None:
            return True
        mj.mj_kinematics(m, data)
        names = [body] if body is not None else self.suction_objects
        best, best_d = None, self.SUCTION_RANGE
        for name in names:
            if self.suction_eq(name) < 0:
                continue
            d = self.cup_distance(data, name)
            if d <= best_d:
                best, best_d = name, d
        if best is None:
            return False
        j = int(m.body_jntadr[m.body(best).id])
        part = j >= 0 and m.jnt_type[j] != mj.mjtJoint.mjJNT_FREE
        self._weld(data, best, torquescale=0.0 if part else 1.0)
        return True

    def _weld(self, data: mujoco.MjData, name: str, *, torquescale: float) -> None:
        m = self.model
        eq = self.suction_eq(name)
        obj = int(m.eq_obj2id[eq])  # the body the weld holds (the object's massive body)
        relpos, relquat = relative_pose(data.xpos[self.cup], data.xquat[self.cup], data.xpos[obj], data.xquat[obj])
        # Weld data layout: anchor(3) in body2's frame, relpos(3) = where that anchor sits in body1's
        # frame, relquat(4) = orientation of body2 in body1, torquescale(1). A full weld anchors at
        # body2's origin; a position-only hold anchors at the cup's centre instead, since a door's frame
        # sits on its hinge, where holding the position would hold nothing.
        anchor = np.zeros(3)
        if torquescale < 1.0:
            anchor = data.xmat[obj].reshape(3, 3).T @ (data.xpos[self.cup] - data.xpos[obj])
            relpos = np.zeros(3)
        m.eq_data[eq, 0:3] = anchor
        m.eq_data[eq, 3:6] = relpos
        m.eq_data[eq, 6:10] = relquat
        m.eq_data[eq, 10] = torquescale
        data.eq_active[eq] = 1

    def release(self, data: mujoco.MjData, body: str | None = None) -> None:
        """Suction off: let go of ``body`` (or of whatever is held)."""
        if body is None:  # every env step without suction comes here: the cached view, no fancy index
            if data is not self._data:
                self._views(data)
            active = self._active
            for eq in self._eq_list:
                if active[eq]:
                    active[eq] = 0
            return
        eq = self.suction_eq(body)
        if eq >= 0:
            data.eq_active[eq] = 0

    # ---------------------------------------------------------------- the action mapping
    def leash(self, data: mujoco.MjData, pos) -> None:
        """Put the end-effector target at ``pos``, but at most TARGET_LEASH from the cup per axis."""
        cup = data.xpos[self.cup]
        data.mocap_pos[self.mocap] = cup + np.clip(np.asarray(pos) - cup, -self.TARGET_LEASH, self.TARGET_LEASH)

    def target_towards(self, data: mujoco.MjData, want, max_step: float) -> None:
        """Move the target at most ``max_step`` metres straight towards ``want`` (leashed): the
        Driver's way of following a line, one control step at a time."""
        delta = np.asarray(want) - data.mocap_pos[self.mocap]
        n = np.linalg.norm(delta)
        if n > max_step:
            delta *= max_step / n
        self.leash(data, data.mocap_pos[self.mocap] + delta)

    def move_target(self, data: mujoco.MjData, action, *, dp: float = STEP_POS, dr: float = STEP_ROT) -> None:
        """Move the target by ``dp * a[:3]`` (leashed) and turn it by the axis-angle ``a[3:6]`` (at most
        ``dr`` rad) in the cup frame. ``action`` is a float64 array whose entries lie in [-1, 1].

        The arithmetic is exactly that of the SAC door benchmark's env, so its learning curves (and
        the tests that pin them) are unchanged: the axis is ``a / (|a| + 1e-9)``, and the target
        quaternion is renormalised every step. Scalar maths where it gives numpy's (or MuJoCo's
        ``mju_axisAngle2Quat``'s) exact values, and numpy's dot and MuJoCo's quaternion product
        (FMA-rounded) where it would not, keep it cheap: it is every env's hot path.
        """
        self._move_target(data, action.tolist(), action, dp, dr)

    def _views(self, data: mujoco.MjData) -> None:
        """Cache views of ``data``'s arrays and the scratch quaternions of :meth:`_move_target`.

        Why memoryviews: each MjData attribute access is a pybind call, and reading or writing three
        or four floats through a memoryview costs a third of numpy's item or slice assignment; the
        env's hot path does it every step. The bytes are MjData's own, so MuJoCo sees every write.
        """
        self._data = data
        self._mquat_arr = data.mocap_quat[self.mocap]  # an array: mju_mulQuat's argument
        self._mpos, self._mquat = memoryview(data.mocap_pos[self.mocap]), memoryview(self._mquat_arr)
        self._cpos, self._active = memoryview(data.xpos[self.cup]), memoryview(data.eq_active)
        self._dq, self._q = np.zeros(4), np.zeros(4)
        self._dq_view, self._q_view = memoryview(self._dq), memoryview(self._q)

    def _move_target(self, data: mujoco.MjData, vals: list, action: np.ndarray, dp: float, dr: float) -> None:
        """:meth:`move_target` on ``vals`` (``action.tolist()``, which :meth:`apply_action` has already)."""
        if data is not self._data:
            self._views(data)
        a0, a1, a2, a3, a4, a5 = vals[:6]
        mpos, mquat, dq = self._mpos, self._mquat, self._dq_view
        mx, my, mz = mpos
        cx, cy, cz = self._cpos
        lim, nlim = self.TARGET_LEASH, -self.TARGET_LEASH
        # cup + clip(target + dp * a - cup): float for float the same operations as numpy's (the
        # comparisons are min(max(v, -lim), lim) without two calls, NaN passing through alike)
        x, y, z = mx + dp * a0 - cx, my + dp * a1 - cy, mz + dp * a2 - cz
        mpos[0] = cx + (nlim if x < nlim else lim if x > lim else x)
        mpos[1] = cy + (nlim if y < nlim else lim if y > lim else y)
        mpos[2] = cz + (nlim if z < nlim else lim if z > lim else z)
        r = action[3:6]
        n = math.sqrt(r.dot(r))  # = np.linalg.norm(r); a Python sum of squares rounds differently
        k = n + 1e-9
        angle = dr * (n if n < 1.0 else 1.0)  # dr * min(1.0, n)
        if angle == 0:  # mju_axisAngle2Quat's own arithmetic, bit for bit (tests/robot/test_agent.py)
            dq[0], dq[1], dq[2], dq[3] = 1.0, 0.0, 0.0, 0.0
        else:
            s = math.sin(angle * 0.5)
            dq[0], dq[1], dq[2], dq[3] = math.cos(angle * 0.5), a3 / k * s, a4 / k * s, a5 / k * s
        q = self._q
        self._mul_quat(q, self._mquat_arr, self._dq)  # q_target * dq: a turn about the cup's own axes
        w, x, y, z = self._q_view
        k = math.sqrt(q.dot(q))  # = np.linalg.norm(q)
        mquat[0], mquat[1], mquat[2], mquat[3] = w / k, x / k, y / k, z / k

    def apply_action(self, data: mujoco.MjData, action, *, dp: float = STEP_POS, dr: float = STEP_ROT) -> np.ndarray:
        """Map one 7-D action onto the target and the suction toggle (no physics step): the one action
        mapping of every env and replay.

        ``a[:6]`` as in :meth:`move_target` with the agent's step size (``STEP_POS``, ``STEP_ROT``);
        ``dp``/``dr`` exist for an env that documents a different one (none does today). ``a[6] > 0``
        grabs by :meth:`grab` (the nearest graspable body in range) unless something is held already,
        ``<= 0`` releases (nothing is held afterwards). Returns the clipped action as a fresh float64
        array (reward action penalties read it).
        """
        try:
            raw = action.tolist()
        except AttributeError:
            raw = list(action)
        if len(raw) != 7 or isinstance(raw[0], list):  # a (1, 7) or (7, 1) array: flatten it
            raw = np.asarray(action, dtype=float).reshape(7).tolist()
        # np.clip's values, cheaper (this runs every env step); the list goes on to the target's maths
        vals = [v if -1.0 <= v <= 1.0 else (1.0 if v > 0 else -1.0) for v in raw]
        a = np.array(vals, dtype=float)
        self._move_target(data, vals, a, dp, dr)
        if not self._eq_list:
            return a
        if vals[6] > 0:
            if self.held(data) is None:
                self.grab(data)
        else:  # a no-op when nothing is held, and cheaper than asking first (every env step runs it)
            self.release(data)
        return a
