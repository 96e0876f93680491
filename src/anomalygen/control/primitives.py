"""Action primitives driven through the end-effector mocap target (the ``ee_track`` weld).

Implemented so far: :func:`push_joint`, the push/pull primitive for hinged and sliding parts (doors,
drawers, lids). It needs no learned policy: the part's kinematics say where to push. A point ``h`` on
a part hinged about axis ``a`` through ``p`` moves along ``a x (h - p)`` when the joint value grows,
so the cup first goes to a pre-contact point 0.05 m on the far side of that direction (behind the
motion), then follows the moving contact point while the joint tracks the goal. A slide joint moves
along its axis. Contact is kept by re-aiming at the part point every step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from anomalygen.scene.robot import LIFT_MAX


@dataclass
class PrimitiveResult:
    success: bool
    steps: int
    detail: str = ""


def _step(env_like, target_pos) -> None:
    """Move the mocap target towards ``target_pos`` at most ``dp`` per control step, then simulate."""
    import mujoco

    m, d = env_like.model, env_like.data
    mid = env_like._mocap
    cup = d.xpos[env_like._cup]
    delta = np.asarray(target_pos) - d.mocap_pos[mid]
    n = np.linalg.norm(delta)
    if n > env_like.dp:
        delta *= env_like.dp / n
    d.mocap_pos[mid] = cup + np.clip(d.mocap_pos[mid] + delta - cup, -0.08, 0.08)
    for _ in range(env_like.frameskip):
        mujoco.mj_step(m, d)


def joint_motion_direction(model, data, joint: str, point: np.ndarray) -> np.ndarray:
    """Unit world direction in which ``point`` (on the part) moves when the joint value increases."""
    import mujoco

    j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
    axis = data.xaxis[j]
    if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE:
        return axis / np.linalg.norm(axis)
    v = np.cross(axis, np.asarray(point) - data.xanchor[j])
    return v / (np.linalg.norm(v) + 1e-12)


def push_joint(env_like, joint: str, goal: float, point_site: str, *, tol: float = 0.08, max_steps: int = 300,
               standoff: float = 0.05, on_step=None) -> PrimitiveResult:
    """Drive ``joint`` to ``goal`` by pushing at the part point ``point_site`` (door handle, drawer front)."""
    import mujoco

    m, d = env_like.model, env_like.data
    sid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, point_site)
    steps = 0

    def q() -> float:
        return float(d.joint(joint).qpos[0])

    sign = -1.0 if goal < q() else 1.0  # push against or along the opening direction
    # 1. approach: to the pre-contact point behind the motion, with a lateral stand-off first
    for phase in ("clear", "precontact"):
        for _ in range(max_steps // 3):
            h = d.site_xpos[sid]
            v = sign * joint_motion_direction(m, d, joint, h)
            pre = h - standoff * v + (np.array([0, 0, 0.0]) if phase == "precontact" else -0.15 * v)
            _step(env_like, pre)
            steps += 1
            if on_step:
                on_step()
            if np.linalg.norm(d.site_xpos[env_like._site_ee] - pre) < 0.02:
                break
    # 2. push: follow the moving point, aiming past it along the motion
    while steps < max_steps and abs(q() - goal) > tol and sign * (goal - q()) > 0:
        h = d.site_xpos[sid]
        v = sign * joint_motion_direction(m, d, joint, h)
        _step(env_like, h + 0.06 * v)
        steps += 1
        if on_step:
            on_step()
    ok = abs(q() - goal) <= tol or sign * (goal - q()) <= 0
    return PrimitiveResult(ok, steps, f"{joint} = {q():.3f} (goal {goal:.3f})")


# --------------------------------------------------------------------------- primitives on built scenes
#
# The functions below work on a scene built by the scene stage (``scene.graph.load_scene``). One
# :class:`Driver` owns the model/data, the mocap end-effector target and the frame hook. The arm is
# driven through the ``ee_track`` weld: the cup follows the mocap body, which is moved along straight
# interpolated waypoints at most ``dp`` metres per control step (``frameskip`` physics steps each).
# The mobile base is placed kinematically: a collision-free pose facing the target at arm's reach is
# chosen from a fixed ring of candidates (deterministic; no base path planning yet), and a held object
# is carried rigidly with it. Given the seed, every run is identical.

PRE_CONTACT = 0.03  # metres off the surface before the straight approach along the normal
BASE_REACH = (0.55, 0.45, 0.65, 0.75)  # base-to-target horizontal distances tried, in order
LIFT_LEVELS = (0.0, LIFT_MAX / 2, LIFT_MAX)  # torso lift heights tried, lowest first


class Driver:
    """Owns a loaded scene and moves the suction cup / base; counts control steps, calls ``on_step``."""

    def __init__(self, model, data, spec, *, frameskip: int = 5, dp: float = 0.012, on_step=None,
                 rng: np.random.Generator | None = None, planned_motion: bool = True):
        import mujoco

        from anomalygen.scene import robot

        self.model, self.data, self.spec = model, data, spec
        self.frameskip, self.dp, self.on_step = int(frameskip), float(dp), on_step
        self.steps = 0
        self.opened: dict[str, list[str]] = {}  # container -> joints opened to put something in
        self.compartments: dict[str, tuple] = {}  # container -> (lo, hi, outward normal) behind its opened door
        self.planned_motion = planned_motion  # reach pre-contact poses by IK + OMPL paths
        self.reaches = True  # did the last base placement satisfy its reach poses?
        self.plan_seed = int(rng.integers(2**31)) if rng is not None else 0
        # The seed only turns the ring of candidate base poses, so seeds try different approach sides.
        self.ring_offset = float(rng.uniform(0.0, 2 * np.pi / 24)) if rng is not None else 0.0
        self._mocap = robot.enable_ee_tracking(model, data)
        self._cup = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "suction")
        self._site_ee = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "suction_site")
        mujoco.mj_forward(model, data)
        r = data.xmat[self._cup].reshape(3, 3)
        self._site_local = r.T @ (data.site_xpos[self._site_ee] - data.xpos[self._cup])
        self._robot_geoms = set(robot.robot_geom_ids(model).tolist())
        self._floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "floor")

    # ---------------------------------------------------------------- low level
    def step(self) -> None:
        import mujoco

        for _ in range(self.frameskip):
            mujoco.mj_step(self.model, self.data)
        self.steps += 1
        if self.on_step is not None:
            self.on_step(self)

    def settle(self, n: int = 20) -> None:
        for _ in range(n):
            self.step()

    def reach_planned(self, goals, quat) -> bool:
        """Cup to the first of ``goals`` reachable by IK and a collision-free OMPL path (``arm_motion``);
        False, with nothing moved, when none is (or planned motion is off): the caller moves straight."""
        if not self.planned_motion:
            return False
        from anomalygen.control.arm_motion import move_arm_planned

        return any(move_arm_planned(self, g, quat, seed=self.plan_seed, ik_attempts=3).ok for g in goals)

    def straighten_wrist(self, lift: float = 0.0, lift_steps: int = 40) -> None:
        """If a pull or side grasp left the cup sideways, rise by ``lift`` and plan back to the home
        configuration: a straight cup-down move from there winds the wrist into the furniture."""
        if not self.planned_motion or self.cup_down():
            return
        from anomalygen.control.arm_motion import rehome

        if lift > 0:
            self.goto(self.site + np.array([0.0, 0.0, lift]), max_steps=lift_steps, tol=0.03)
        rehome(self, seed=self.plan_seed)

    def cup_down(self, cos_tol: float = 0.7) -> bool:
        """True when the cup face points roughly down (within ~45 degrees)."""
        return bool(-self.data.xmat[self._cup].reshape(3, 3)[2, 2] > cos_tol)

    @property
    def site(self) -> np.ndarray:
        return self.data.site_xpos[self._site_ee].copy()

    def goto(self, target, quat=None, *, tol: float = 0.012, max_steps: int = 250) -> bool:
        """Move the cup face (``suction_site``) to ``target`` with the cup oriented as ``quat``."""
        import mujoco

        d = self.data
        target = np.asarray(target, dtype=float)
        if quat is not None:
            d.mocap_quat[self._mocap] = quat
        for _ in range(max_steps):
            rq = np.zeros(9)
            mujoco.mju_quat2Mat(rq, d.mocap_quat[self._mocap])
            want = target - rq.reshape(3, 3) @ self._site_local
            delta = want - d.mocap_pos[self._mocap]
            n = np.linalg.norm(delta)
            if n > self.dp:
                delta *= self.dp / n
            cup = d.xpos[self._cup]
            d.mocap_pos[self._mocap] = cup + np.clip(d.mocap_pos[self._mocap] + delta - cup, -0.08, 0.08)
            self.step()
            if np.linalg.norm(self.site - target) < tol:
                return True
        return bool(np.linalg.norm(self.site - target) < 2 * tol)

    # ---------------------------------------------------------------- scene queries
    def body_id(self, name: str) -> int:
        import mujoco

        return mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_BODY, name)

    def joint_body(self, joint: str) -> str:
        """Name of the body a joint moves (a drawer's box, a door's panel)."""
        return self.model.body(int(self.model.joint(joint).bodyid[0])).name

    def aabb(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """World AABB of all geoms of body ``name`` and its descendants (collision geoms first)."""
        from anomalygen.scene import robot
        from anomalygen.scene.graph import geom_world_aabbs

        mask = robot._subtree_geoms(self.model, self.body_id(name))
        lo, hi = geom_world_aabbs(self.model, self.data)
        coll = mask & (self.model.geom_contype | self.model.geom_conaffinity).astype(bool)
        use = coll if coll.any() else mask
        return lo[use].min(axis=0), hi[use].max(axis=0)

    def _robot_in_collision(self) -> bool:
        """Robot or the object it holds penetrating the world (the floor under the base excepted)."""
        from anomalygen.scene import robot

        d = self.data
        held = self.held
        carried = robot._subtree_geoms(self.model, self.body_id(held)) if held is not None else None
        for i in range(d.ncon):
            g1, g2 = int(d.contact.geom1[i]), int(d.contact.geom2[i])
            r1 = g1 in self._robot_geoms or (carried is not None and carried[g1])
            r2 = g2 in self._robot_geoms or (carried is not None and carried[g2])
            if r1 != r2 and self._floor not in (g1, g2) and d.contact.dist[i] < -0.002:
                return True
        return False

    def _in_body(self, geom: int, name: str) -> bool:
        from anomalygen.scene import robot

        return bool(robot._subtree_geoms(self.model, self.body_id(name))[geom])

    @property
    def held(self) -> str | None:
        from anomalygen.scene import robot

        return robot.held_object(self.model, self.data)

    # ---------------------------------------------------------------- base
    def place_base_near(self, point, *, reach=BASE_REACH, side=None, tuck: bool = True, reach_poses=()) -> bool:
        """Put the base at a collision-free pose facing ``point`` at arm's reach (kinematic move).

        Candidates: rings of 24 headings at each distance in ``reach``, tried nearest-to-current first;
        with ``side`` (a horizontal direction from the point), only poses on that side (within 70 deg).
        With ``reach_poses`` ((pos, quat) pairs) a pose must also let the arm reach each of them by IK
        (else the first free pose is taken); the torso lift stays down unless only a raised arm
        reaches them (a lid on a box on a counter), then it rises in steps. A held object is carried
        rigidly with the base. Returns False (base unchanged) if none is free.
        """
        import mujoco

        from anomalygen.scene import robot

        m, d = self.model, self.data
        p = np.asarray(point, dtype=float)
        cur = np.array([d.joint(j).qpos[0] for j in robot.BASE_JOINTS])
        sd = None if side is None else np.asarray(side, dtype=float)[:2] / (np.linalg.norm(np.asarray(side)[:2]) + 1e-9)
        on_side = (lambda b: True) if sd is None else (
            lambda b: float(np.dot(b - p[:2], sd)) > 0.34 * float(np.linalg.norm(b - p[:2])))
        lift0 = robot.lift(m)
        if (np.hypot(*(p[:2] - cur[:2])) < 0.62 and self._facing(cur, p) and on_side(cur[:2])
                and (lift0 < 0.01 or reach_poses) and self._reaches(reach_poses)):
            return True
        saved = (d.qpos.copy(), d.qvel.copy(), d.mocap_pos.copy(), d.mocap_quat.copy())
        held = self.held
        hb = self.body_id(held) if held else -1
        hq = m.jnt_qposadr[m.body_jntadr[hb]] if held and m.body_jntadr[hb] >= 0 else -1
        for lift in LIFT_LEVELS if reach_poses else LIFT_LEVELS[:1]:
            for r in reach:
                angles = self.ring_offset + np.linspace(0, 2 * np.pi, 24, endpoint=False)
                cands = [b for b in (p[:2] + r * np.array([np.cos(a), np.sin(a)]) for a in angles) if on_side(b)]
                cands.sort(key=lambda b: float(np.hypot(*(b - cur[:2]))))
                for b in cands:
                    yaw = float(np.arctan2(p[1] - b[1], p[0] - b[0]))
                    self._move_base_rigid(np.array([*cur, lift0]), np.array([b[0], b[1], yaw, lift]), saved, hq)
                    mujoco.mj_forward(m, d)
                    if not self._robot_in_collision() and self._reaches(reach_poses):
                        for j, v in zip(robot.BASE_JOINTS, (b[0], b[1], yaw), strict=True):
                            d.actuator(j).ctrl[0] = v
                        d.qvel[:] = 0.0
                        self.settle(10)
                        self.reaches = True
                        return True
        d.qpos[:], d.qvel[:], d.mocap_pos[:], d.mocap_quat[:] = saved
        robot.set_lift(m, d, lift0)
        mujoco.mj_forward(m, d)
        if tuck and self.tuck():  # an outstretched arm collides everywhere: fold it in and try again
            return self.place_base_near(point, reach=reach, side=side, tuck=False, reach_poses=reach_poses)
        if reach_poses:  # nowhere reaches every pose: settle for a free pose (and say so in .reaches)
            ok = self.place_base_near(point, reach=reach, side=side, tuck=False)
            self.reaches = False
            return ok
        return False

    def _reaches(self, poses) -> bool:
        """Can the arm (base where it is now) put the cup face at each (pos, quat)? IK on a copy."""
        if not poses:
            return True
        from anomalygen.control.ik import solve_ik
        from anomalygen.scene import robot

        home = np.asarray(robot.HOME_ARM, dtype=float)
        for pos, quat in poses:
            r = solve_ik(self.model, self.data, "suction_site", robot.ARM_JOINTS, pos, quat, q_init=home,
                         iterations=150)
            if not r.success:
                return False
        return True

    def tuck(self) -> bool:
        """Bring the cup (and anything held) in close above the base, cup down, before a base move."""
        from anomalygen.control.ik import quat_z_to
        from anomalygen.scene import robot

        d = self.data
        x, y, yaw = (float(d.joint(j).qpos[0]) for j in robot.BASE_JOINTS)
        here = np.array([x + 0.35 * np.cos(yaw), y + 0.35 * np.sin(yaw), max(0.9, float(self.site[2]))])
        self.goto(np.array([*self.site[:2], here[2]]), quat_z_to(np.array([0.0, 0.0, -1.0])), max_steps=60)
        return self.goto(here, max_steps=120, tol=0.03)

    @staticmethod
    def _facing(base, p) -> bool:
        want = np.arctan2(p[1] - base[1], p[0] - base[0])
        return abs((want - base[2] + np.pi) % (2 * np.pi) - np.pi) < 0.6

    def _move_base_rigid(self, cur, new, saved, hq) -> None:
        """Set the base joints and torso lift to ``new`` (x, y, yaw, lift) and carry the mocap target
        (and a held object) rigidly along."""
        import mujoco

        from anomalygen.scene import robot

        d = self.data
        qpos0, _, mpos0, mquat0 = saved
        d.qpos[:] = qpos0
        for j, v in zip(robot.BASE_JOINTS, new[:3], strict=True):
            d.joint(j).qpos[0] = v
        robot.set_lift(self.model, d, new[3])
        dyaw = new[2] - cur[2]
        c, s = np.cos(dyaw), np.sin(dyaw)
        rz = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])
        qz = np.array([np.cos(dyaw / 2), 0, 0, np.sin(dyaw / 2)])
        base0 = np.array([cur[0], cur[1], cur[3]])
        base1 = np.array([new[0], new[1], new[3]])

        def carry(pos, quat):
            q = np.zeros(4)
            mujoco.mju_mulQuat(q, qz, quat)
            return rz @ (pos - base0) + base1, q

        d.mocap_pos[self._mocap], d.mocap_quat[self._mocap] = carry(mpos0[self._mocap], mquat0[self._mocap])
        if hq >= 0:
            d.qpos[hq:hq + 3], d.qpos[hq + 3:hq + 7] = carry(qpos0[hq:hq + 3], qpos0[hq + 3:hq + 7])


def _top_contact(drv: Driver, obj: str):
    """Grasp point and outward normal: the centre of the object's top face (AABB), normal +z."""
    return grasp_points(drv, obj)[0], np.array([0.0, 0.0, 1.0])


def grasp_points(drv: Driver, obj: str, n: int = 3) -> list[np.ndarray]:
    """Up to ``n`` points to put the cup on, best first: the tops of the object's highest, widest
    collision geoms, then the centre of its box's top. A pair of pliers or glasses has nothing
    under the centre of its box, so the box alone sends the cup into a gap."""
    from anomalygen.scene import robot
    from anomalygen.scene.graph import geom_world_aabbs

    m = drv.model
    lo, hi = drv.aabb(obj)
    glo, ghi = geom_world_aabbs(m, drv.data)
    mask = robot._subtree_geoms(m, drv.body_id(obj)) & (m.geom_contype | m.geom_conaffinity).astype(bool)
    cands = []
    for g in np.flatnonzero(mask):
        area = float(np.prod(ghi[g, :2] - glo[g, :2]))
        top = float(ghi[g, 2])
        if top < hi[2] - 0.03:
            continue  # well below the top: the cup would meet something else first
        cands.append((top - hi[2] + 3.0 * np.sqrt(area), np.array([*(glo[g, :2] + ghi[g, :2]) / 2, top])))
    cands.sort(key=lambda c: -c[0])
    pts: list[np.ndarray] = []
    for _, p in cands:
        if all(np.linalg.norm(p[:2] - q[:2]) > 0.02 for q in pts):
            pts.append(p)
    centre = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2]])
    if all(np.linalg.norm(centre[:2] - q[:2]) > 0.02 for q in pts):
        pts.append(centre)
    return pts[:n]


def approach(drv: Driver, obj: str, point=None) -> PrimitiveResult:
    """Base near ``obj``, cup to 0.03 m above its top face (grasp ``point``), cup facing the surface.

    The pre-contact pose is reached by IK and a collision-free joint path (``arm_motion``), as the
    paper does; when planning fails the cup rises and comes down straight instead."""
    from anomalygen.control.ik import quat_z_to

    s0 = drv.steps
    normal = np.array([0.0, 0.0, 1.0])
    point = grasp_points(drv, obj)[0] if point is None else point
    quat = quat_z_to(-normal)
    pre = point + normal * PRE_CONTACT
    hover = point + normal * (PRE_CONTACT + 0.12)
    # a base pose from which the cup reaches the object face-down (a globe's top is 1.2 m up: from
    # the wrong spot the cup meets it tilted and the globe hangs crooked)
    if not drv.place_base_near(point, reach_poses=[(pre, quat), (hover, quat)]):
        return PrimitiveResult(False, drv.steps - s0, f"no collision-free base pose near {obj}")
    planned = drv.reach_planned((pre, hover), quat)  # the hover pose is freer when pre-contact is cramped
    if not planned:  # rise, turn the cup face-down while clear of everything, then come over and down
        drv.straighten_wrist()
        up = drv.site + np.array([0, 0, max(0.0, hover[2] - drv.site[2])])
        drv.goto(up, max_steps=120)
        drv.goto(up, quat, max_steps=60)
        drv.goto(hover, quat, max_steps=200)
    ok = drv.goto(pre, quat, max_steps=200)
    return PrimitiveResult(ok, drv.steps - s0, f"pre-contact {'reached' if ok else 'not reached'} above {obj}")


def grasp(drv: Driver, obj: str, *, lift: float = 0.12) -> PrimitiveResult:
    """Approach, move along the normal until the cup touches, switch suction on, lift by ``lift``.

    Tries up to three grasp points (``grasp_points``) before giving up."""
    from anomalygen.control.ik import quat_z_to
    from anomalygen.scene import robot

    s0 = drv.steps
    normal = np.array([0.0, 0.0, 1.0])
    quat = quat_z_to(-normal)
    grabbed, tried_side = False, False
    for point in grasp_points(drv, obj):
        res = approach(drv, obj, point)
        if not res.success and "base" in res.detail:
            return res
        if (not drv.reaches and not tried_side and drv.aabb(obj)[1][2] - drv.aabb(obj)[0][2] > 0.2
                and footprint(drv, obj)[2] > 0.09):  # bulky, not a thin screen that a side push would topple
            # a tall object whose top the cup cannot reach face-down: hold it by the side if possible
            tried_side = True
            side = side_grasp(drv, obj, lift=lift)
            if side.success:
                return PrimitiveResult(True, drv.steps - s0, side.detail)
            drv.straighten_wrist(lift=0.1)  # back from the side pose before trying the top
            res = approach(drv, obj, point)
        for k in range(40):  # descend 2.5 mm per waypoint until suction catches
            target = point + normal * (PRE_CONTACT - 0.0025 * k)
            drv.goto(target, quat, max_steps=12, tol=0.004)
            if robot.object_distance_to_cup(drv.model, drv.data, obj) < robot.SUCTION_RANGE * 0.8:
                grabbed = robot.suction_on(drv.model, drv.data, obj)
                if grabbed:
                    break
        if grabbed:
            break
        drv.goto(drv.site + normal * 0.06, quat, max_steps=40)
    if not grabbed:
        return PrimitiveResult(False, drv.steps - s0, f"suction did not catch {obj} "
                               f"(cup-object distance {robot.object_distance_to_cup(drv.model, drv.data, obj):.3f} m)")
    drv.goto(drv.site + np.array([0, 0, lift]), quat, max_steps=150)
    return PrimitiveResult(True, drv.steps - s0, f"holding {obj}, lifted {lift:.2f} m")


def side_grasp(drv: Driver, obj: str, *, lift: float = 0.12) -> PrimitiveResult:
    """Hold a tall object by the side of its widest part, cup horizontal (a globe's top is beyond
    the arm's reach with the cup face-down). The cup comes from the robot's side along a ray to the
    surface; the weld then holds the object's body, so it is carried upright."""
    import mujoco

    from anomalygen.control.ik import quat_z_to
    from anomalygen.scene import robot
    from anomalygen.scene.graph import geom_world_aabbs

    s0 = drv.steps
    m, d = drv.model, drv.data
    glo, ghi = geom_world_aabbs(m, d)
    mask = robot._subtree_geoms(m, drv.body_id(obj)) & (m.geom_contype | m.geom_conaffinity).astype(bool)
    g = max(np.flatnonzero(mask), key=lambda k: float(np.prod(ghi[k, :2] - glo[k, :2])))
    centre = (glo[g] + ghi[g]) / 2
    base = np.array([float(d.joint(j).qpos[0]) for j in robot.BASE_JOINTS[:2]])
    a0 = float(np.arctan2(*(base - centre[:2])[::-1]))
    geomid = np.zeros(1, dtype=np.int32)
    for a in a0 + np.array([0, 1, -1, 2, -2, 3, -3, 4]) * np.pi / 4:  # from the robot's side first
        n = np.array([np.cos(a), np.sin(a), 0.0])
        quat = quat_z_to(-n)
        dist = mujoco.mj_ray(m, d, centre + n * 0.5, -n, None, 1, -1, geomid)
        if dist < 0 or not mask[int(geomid[0])]:
            continue  # something else stands in front of the object on this side
        point = centre + n * (0.5 - dist)
        pre = point + n * PRE_CONTACT
        if drv.place_base_near(point, side=n, reach_poses=[(pre, quat), (pre + n * 0.1, quat)]) and drv.reaches:
            break
    else:
        return PrimitiveResult(False, drv.steps - s0, f"no base pose reaches the side of {obj}")
    if not drv.reach_planned((pre, pre + n * 0.1), quat):
        drv.goto(drv.site + np.array([0, 0, max(0.0, pre[2] + 0.1 - drv.site[2])]), max_steps=100)
        drv.goto(pre + n * 0.1, quat, max_steps=250, tol=0.02)
    drv.goto(pre, quat, max_steps=150)
    for k in range(40):
        drv.goto(point + n * (PRE_CONTACT - 0.0025 * k), quat, max_steps=10, tol=0.004)
        if robot.object_distance_to_cup(m, d, obj) < robot.SUCTION_RANGE * 0.8 and robot.suction_on(m, d, obj):
            drv.goto(drv.site + np.array([0, 0, lift]), quat, max_steps=150)
            return PrimitiveResult(True, drv.steps - s0, f"holding {obj} by its side, lifted {lift:.2f} m")
    drv.goto(drv.site + n * 0.08, quat, max_steps=40)
    return PrimitiveResult(False, drv.steps - s0, f"suction did not catch the side of {obj}")


def release(drv: Driver) -> PrimitiveResult:
    from anomalygen.scene import robot

    s0 = drv.steps
    held = drv.held
    robot.suction_off(drv.model, drv.data)
    drv.settle(15)
    return PrimitiveResult(held is not None, drv.steps - s0, f"released {held}" if held else "nothing held")


def _opened_drawer(drv: Driver, region: str) -> str | None:
    """The drawer joint that ``open_for_access`` pulled out of ``region``, if any."""
    from anomalygen.control import parts

    return next((j for j in drv.opened.get(region, []) if drv.model.jnt_type[drv.model.joint(j).id] == parts.SLIDE),
                None)


def _rim_z(drv: Driver, region: str) -> float:
    """Height the bottom of an object carried into ``region`` must clear: the top of the drawer pulled
    out of it, else the top of its opening."""
    drawer = _opened_drawer(drv, region)
    if drawer is not None:
        return float(drv.aabb(drv.joint_body(drawer))[1][2])
    return float(opening(drv, region)[1][2])


def _drop_point(drv: Driver, region: str, obj: str) -> np.ndarray:
    """Where to hold the object's bottom before release: above the opening of the container's carcass
    (an open lid's own box does not count), inside an opened drawer's exposed part, or above the
    centre of a support's top."""
    from anomalygen.control import parts

    drawer = _opened_drawer(drv, region)
    if drawer is not None:
        dlo, dhi = drv.aabb(drv.joint_body(drawer))
        clo, chi = parts.static_box(drv, region)
        axis = np.abs(drv.data.xaxis[drv.model.joint(drawer).id])
        k = int(np.argmax(axis[:2]))
        centre = (dlo + dhi) / 2
        # the stretch of the drawer that sticks out of the carcass, along the slide axis
        if dhi[k] > chi[k]:
            centre[k] = (max(dlo[k], chi[k]) + dhi[k]) / 2
        elif dlo[k] < clo[k]:
            centre[k] = (dlo[k] + min(dhi[k], clo[k])) / 2
        top = np.array([centre[0], centre[1], dhi[2] + 0.03])
        floor = _floor_below(drv, top, obj)
        return top if floor is None else np.array([centre[0], centre[1], floor - 0.01])
    lo, hi = opening(drv, region)
    centre = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2] + 0.04])
    # Set the object down inside rather than drop it from the rim: the contacts are soft (20 ms), so
    # a needle or a flat wrapper falling even 2 cm sinks past the middle of an 8 mm bottom and is
    # pushed out underneath. The floor inside is found by a ray; the lowering stops at first touch.
    floor = _floor_below(drv, centre, obj)
    if floor is not None:
        centre[2] = min(max(floor - 0.01, hi[2] - MAX_REACH_IN), hi[2] + 0.04)
    return centre


MAX_REACH_IN = 0.5  # m the held object's bottom may go below a container's rim


def _floor_below(drv: Driver, point: np.ndarray, obj: str) -> float | None:
    """Height of the first surface under ``point`` (the held object and the robot ignored)."""
    import mujoco

    from anomalygen.scene import robot

    m, d = drv.model, drv.data
    skip = robot._subtree_geoms(m, drv.body_id(obj)) | np.isin(np.arange(m.ngeom), list(drv._robot_geoms))
    start = np.asarray(point, dtype=float).copy()
    geomid = np.zeros(1, dtype=np.int32)
    for _ in range(8):  # step past ignored geoms
        dist = mujoco.mj_ray(m, d, start, np.array([0.0, 0.0, -1.0]), None, 1, -1, geomid)
        if dist < 0:
            return None
        hit = start[2] - dist
        if not skip[int(geomid[0])]:
            return float(hit)
        start[2] = hit - 1e-4
    return None


def top_rect(drv: Driver, support: str) -> tuple[np.ndarray, np.ndarray]:
    """World box of a support's top board (not the legs' footprint), its height the top's."""
    from anomalygen.scene.graph import geom_world_aabbs

    m = drv.model
    lo, hi = drv.aabb(support)
    glo, ghi = geom_world_aabbs(m, drv.data)
    top_geoms = [g for g in range(m.ngeom) if m.body(int(m.geom_bodyid[g])).name.startswith(support + "/")
                 and ghi[g, 2] > hi[2] - 0.01]
    if top_geoms:
        lo = np.min(glo[top_geoms], axis=0)
        hi = np.array([*np.max(ghi[top_geoms], axis=0)[:2], hi[2]])
    return lo, hi


def free_spot(drv: Driver, support: str, obj: str, *, edge_margin: float = 0.2, turned: bool = True) -> np.ndarray:
    """A drop point on the support's top that keeps ``edge_margin`` from its edges and misses the
    other things standing there (a book in the middle of the table would leave the object perched
    half on it), nearest the centre; the centre when the top is too small for the margin.

    ``turned``: the object will be turned to lie along the top's long side (``move_to`` does that
    for objects with a long side); otherwise it keeps its present orientation."""

    lo, hi = top_rect(drv, support)
    if turned:
        _, a, b = footprint(drv, obj)
        half = np.array([a, b]) if hi[0] - lo[0] >= hi[1] - lo[1] else np.array([b, a])
    else:
        olo, ohi = drv.aabb(obj)
        half = (ohi[:2] - olo[:2]) / 2
    others = []
    for o in drv.spec.objects:
        if o.name in (obj, support):
            continue
        blo, bhi = drv.aabb(o.name)
        if bhi[2] > hi[2] - 0.01 and blo[2] < hi[2] + 0.3:
            others.append((blo[:2] - 0.03, bhi[:2] + 0.03))
    centre = (lo[:2] + hi[:2]) / 2
    inset = np.minimum(half + 0.02, (hi[:2] - lo[:2]) / 2)
    best, best_score = centre, np.inf
    # Score a 31 x 31 grid (a 4 cm step can miss the one clear spot on a crowded table): landing on something else costs most, then ending within NEAR_EDGE of an
    # edge (the hazard itself), then falling short of the wider margin, then distance from the centre.
    for x in np.linspace(lo[0] + inset[0], hi[0] - inset[0], 31):
        for y in np.linspace(lo[1] + inset[1], hi[1] - inset[1], 31):
            p = np.array([x, y])
            hits = sum(bool(np.all(p + half > a) and np.all(p - half < b)) for a, b in others)
            edge = float(np.min(np.minimum(p - half - lo[:2], hi[:2] - p - half)))
            score = (hits * 10.0 + 20.0 * max(0.0, NEAR_EDGE + 0.02 - edge) + 5.0 * max(0.0, edge_margin - edge)
                     + 0.1 * float(np.linalg.norm(p - centre)))
            if score < best_score:
                best, best_score = p, score
    return np.array([best[0], best[1], hi[2] - 0.01])  # set down until it touches: a dropped globe topples


def opening(drv: Driver, region: str) -> tuple[np.ndarray, np.ndarray]:
    """The box above which a dropped object falls into ``region``: the carcass's top rectangle, minus
    the strip that a half-open lid still hangs over (the lid swings about a horizontal axis, so it
    covers the side of the opening next to its hinge)."""
    from anomalygen.control import parts

    if not drv.opened.get(region):
        return drv.aabb(region)
    lo, hi = (v.copy() for v in parts.static_box(drv, region))
    m = drv.model
    for jn in drv.opened[region]:
        j = m.joint(jn).id
        if m.jnt_type[j] != parts.HINGE:
            continue
        axis = drv.data.xaxis[j]
        k = 1 if abs(axis[0]) > abs(axis[1]) else 0  # horizontal direction the part swings along
        plo, phi = drv.aabb(m.body(int(m.jnt_bodyid[j])).name)
        if phi[k] <= lo[k] or plo[k] >= hi[k]:
            continue  # swung clear of the opening
        below, above = plo[k] - lo[k], hi[k] - phi[k]
        if below >= above:
            hi[k] = max(lo[k] + 1e-3, plo[k])
        else:
            lo[k] = min(hi[k] - 1e-3, phi[k])
    return lo, hi


def _long_axis_yaw(drv: Driver, obj: str) -> float:
    """Yaw of the held object's longest horizontal extent (principal axis of its geoms' corners)."""
    return footprint(drv, obj)[0]


def footprint(drv: Driver, obj: str) -> tuple[float, float, float]:
    """(yaw of the long side, half length, half width) of the object seen from above."""
    from anomalygen.scene import robot

    m, d = drv.model, drv.data
    mask = robot._subtree_geoms(m, drv.body_id(obj))
    pts = []
    for g in np.flatnonzero(mask):
        c, h = m.geom_aabb[g, :3], m.geom_aabb[g, 3:]
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h + c
        pts.append(corners @ d.geom_xmat[g].reshape(3, 3).T + d.geom_xpos[g])
    xy = np.concatenate(pts)[:, :2]
    xy = xy - xy.mean(axis=0)
    w, v = np.linalg.eigh(xy.T @ xy)
    major = v[:, int(np.argmax(w))]
    minor = np.array([-major[1], major[0]])
    along, across = xy @ major, xy @ minor
    return (float(np.arctan2(major[1], major[0])), float(np.ptp(along)) / 2, float(np.ptp(across)) / 2)


def _yawed(quat: np.ndarray, yaw: float) -> np.ndarray:
    import mujoco

    out = np.zeros(4)
    mujoco.mju_mulQuat(out, np.array([np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)]), quat)
    return out


def move_to(drv: Driver, obj: str, region: str, *, release_after: bool = True, into: bool = True) -> PrimitiveResult:
    """Carry the held ``obj`` above ``region`` and lower it: into a container's opening (``into``) or
    onto a free spot of a support's top; then release."""
    from anomalygen.control.ik import quat_z_to

    s0 = drv.steps
    if drv.held != obj:
        return PrimitiveResult(False, 0, f"{obj} is not held")
    if into and region in drv.compartments:
        return place_through_door(drv, obj, region, release_after=release_after)
    face_down = drv.cup_down(0.7)
    yaw, a, b = footprint(drv, obj)
    # Turn the object so its long side runs along the long side of the opening (or of the table top),
    # but only when it hangs below a face-down cup and, on a table, has a long side: a turn swings a
    # side-held globe so that it lands tilted, and gains nothing for a square camera.
    turning = face_down and (into or a > SQUARE_RATIO * b)
    goal = _drop_point(drv, region, obj) if into else free_spot(drv, region, obj, turned=turning)
    olo, ohi = drv.aabb(obj)
    below = drv.site[2] - olo[2]  # cup face to object bottom
    # carry face-down, or as held for a side grasp (turning the cup would turn the object over)
    quat = quat_z_to(np.array([0.0, 0.0, -1.0])) if face_down else drv.data.mocap_quat[drv._mocap].copy()
    lo, hi = opening(drv, region) if into else top_rect(drv, region)
    # carried high enough that the object's bottom clears the container's rim (a box on a counter is
    # deeper than the 0.1 m above its floor that the set-down point gives)
    rim = _rim_z(drv, region) if into else hi[2]
    carry_z = max(drv.site[2], goal[2] + below + 0.1, rim + below + 0.05)
    drv.goto(np.array([*drv.site[:2], carry_z]), quat, max_steps=150)
    want = 0.0 if hi[0] - lo[0] >= hi[1] - lo[1] else np.pi / 2
    turn = (want - yaw + np.pi / 2) % np.pi - np.pi / 2 if turning else 0.0
    final = _yawed(quat, turn)
    # Aim the object, not the cup: held by its side (or off-centre), the object's centre is well away
    # from the cup, so the base is placed for the cup poses that put the object's centre on the goal.
    olo, ohi = drv.aabb(obj)
    off = (olo[:2] + ohi[:2]) / 2 - drv.site[:2]
    off = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]]) @ off
    cup_goal = np.array([*(goal[:2] - off), goal[2]])
    above, low = np.array([*cup_goal[:2], carry_z]), cup_goal + np.array([0, 0, below])
    if not drv.place_base_near(cup_goal, reach_poses=[(above, final), (low, final)]):
        return PrimitiveResult(False, drv.steps - s0, f"no collision-free base pose near {region}")
    if not drv.reach_planned((above,), final):
        drv.goto(above, quat, max_steps=250)
        for f in np.linspace(0.2, 1.0, 5):
            drv.goto(above, _yawed(quat, f * turn), max_steps=8)
    quat = final
    _let_swing_die(drv, obj)
    below = drv.site[2] - drv.aabb(obj)[0][2]  # again: the swing and the turn change how the object hangs
    low = np.array([low[0], low[1], goal[2] + below])
    # correct what is left of the object's offset from the spot (the base pose only approximates it)
    for _ in range(2):
        olo, ohi = drv.aabb(obj)
        err = goal[:2] - (olo[:2] + ohi[:2]) / 2
        if np.linalg.norm(err) < 0.01:
            break
        above = np.array([above[0] + err[0], above[1] + err[1], above[2]])
        low = np.array([low[0] + err[0], low[1] + err[1], low[2]])
        drv.goto(above, quat, max_steps=120, tol=0.01)
        _let_swing_die(drv, obj)
    ok = lower_until_contact(drv, obj, low, quat)
    if release_after:
        release(drv)
        drv.goto(drv.site + np.array([0, 0, 0.1]), quat, max_steps=60)
    return PrimitiveResult(ok, drv.steps - s0, f"{obj} {'lowered' if ok else 'not fully lowered'} over {region}")


def place_through_door(drv: Driver, obj: str, region: str, *, release_after: bool = True) -> PrimitiveResult:
    """Slide the held object into the compartment behind an opened door and set it on its floor.

    The cup stays face-down, so the object is carried level at a height just clearing the
    compartment's floor, turned to lie across the opening, pushed in horizontally, lowered until it
    touches, released; the cup then backs out the way it came."""
    from anomalygen.control.ik import quat_z_to

    s0 = drv.steps
    lo, hi, out = drv.compartments[region]
    centre = (lo + hi) / 2
    floor = _floor_below(drv, np.array([centre[0], centre[1], hi[2] - 0.01]), obj)
    floor = float(lo[2]) if floor is None else floor
    olo, ohi = drv.aabb(obj)
    below = drv.site[2] - olo[2]
    quat = quat_z_to(np.array([0.0, 0.0, -1.0]))
    across = 0.0 if abs(out[0]) > abs(out[1]) else np.pi / 2  # long side along the opening's width
    turn = (across + np.pi / 2 - _long_axis_yaw(drv, obj) + np.pi / 2) % np.pi - np.pi / 2
    final = _yawed(quat, turn)
    depth = float(np.dot(hi - lo, np.abs(out)))
    z = floor + below + 0.015
    inside = np.array([centre[0], centre[1], z])
    front = inside + out * (depth / 2 + 0.2)
    drv.goto(np.array([*drv.site[:2], max(drv.site[2], z + 0.1)]), quat, max_steps=150)
    if not drv.place_base_near(front, side=out, reach_poses=[(front, final), (inside, final)]):
        return PrimitiveResult(False, drv.steps - s0, f"no base pose in front of {region}'s open door")
    drv.goto(np.array([*front[:2], max(drv.site[2], z)]), final, max_steps=250)
    drv.goto(front, final, max_steps=150)
    ok = drv.goto(inside, final, max_steps=200, tol=0.02)
    lower_until_contact(drv, obj, inside - np.array([0, 0, 0.05]), final)
    if release_after:
        release(drv)
        drv.goto(drv.site + np.array([0, 0, 0.01]), final, max_steps=20)
        drv.goto(np.array([*front[:2], drv.site[2]]), final, max_steps=150)
    return PrimitiveResult(ok, drv.steps - s0, f"{obj} {'slid into' if ok else 'not fully into'} {region} through its door")


def _let_swing_die(drv: Driver, obj: str, max_steps: int = 40) -> None:
    """Hold still until the carried object stops swinging: set down while swinging, it lands tilted."""
    b = drv.body_id(obj)
    for _ in range(max_steps):
        w, v = drv.data.cvel[b][:3], drv.data.cvel[b][3:]
        if np.linalg.norm(w) < 0.15 and np.linalg.norm(v) < 0.02:
            return
        drv.step()


def lower_until_contact(drv: Driver, obj: str, target, quat, *, max_steps: int = 300, tol: float = 0.02) -> bool:
    """Lower the held object towards ``target`` (cup face) and stop the moment it touches anything.

    A guarded move: the weld is stiff, so pressing on would push a needle through a thin bottom. It
    also stops where the arm can reach no lower with the cup upright (deep in a box on the floor the
    wrist tilts and the swinging object knocks the lid shut). True when the target was reached or
    the object came to rest on something."""
    target = np.asarray(target, dtype=float)
    upright = drv.cup_down(0.9)
    dp = drv.dp
    try:
        for _ in range(max_steps):
            if held_touches(drv, obj):
                return True
            if upright and not drv.cup_down(0.9):  # as low as the arm goes with the cup upright: let go
                return True
            # the last 8 cm slowly (3 mm a step): at full speed a 4 mm bottom is crossed between checks
            drv.dp = SLOW_DP if drv.site[2] - target[2] < 0.08 else dp
            drv.goto(target, quat, max_steps=1, tol=0.0)
            if np.linalg.norm(drv.site - target) < tol:
                return True
        return False
    finally:
        drv.dp = dp


SQUARE_RATIO = 1.3  # an object whose footprint is less elongated than this is not turned before a set-down
NEAR_EDGE = 0.15  # m: the knowledge base's near_edge distance for fragile things (move_fragile_from_edge)
SLOW_DP = 0.003  # m per control step for the final part of a set-down


def held_touches(drv: Driver, obj: str) -> bool:
    """Does the held object touch something other than the robot?"""
    from anomalygen.scene import robot

    d = drv.data
    mask = robot._subtree_geoms(drv.model, drv.body_id(obj))
    for i in range(d.ncon):
        g1, g2 = int(d.contact.geom1[i]), int(d.contact.geom2[i])
        if mask[g1] == mask[g2]:
            continue
        other = g2 if mask[g1] else g1
        if other not in drv._robot_geoms and d.contact.dist[i] < 0.0005:
            return True
    return False


def surface_centre_of(drv: Driver, obj: str) -> str | None:
    """The support under ``obj`` according to the scene spec."""
    for o in drv.spec.objects:
        if o.name == obj:
            return o.support if o.support and o.support != "floor" else None
    return None


def part_point_local(drv: Driver, joint: str) -> tuple[int, np.ndarray]:
    """A point on the moving part, in the part body frame: the AABB centre pushed out far from a hinge."""
    j = drv.model.joint(joint)
    body = int(j.bodyid[0])
    name = drv.model.body(body).name
    lo, hi = drv.aabb(name)
    c = (lo + hi) / 2
    if drv.model.jnt_type[j.id] == 3:  # hinge: 80 % of the way from the axis to the far edge
        anchor = drv.data.xanchor[j.id]
        axis = drv.data.xaxis[j.id]
        corners = np.array([[x, y, c[2]] for x in (lo[0], hi[0]) for y in (lo[1], hi[1])])
        rel = corners - anchor
        perp = rel - np.outer(rel @ axis, axis)
        far = corners[int(np.argmax(np.linalg.norm(perp, axis=1)))]
        c = anchor + (far - anchor) * 0.8
        c = c + axis * (np.dot((lo + hi) / 2 - anchor, axis) - np.dot(c - anchor, axis))
    r = drv.data.xmat[body].reshape(3, 3)
    return body, r.T @ (c - drv.data.xpos[body])


def push_part(drv: Driver, joint: str, goal: float, *, tol: float = 0.08, max_steps: int = 500,
              standoff: float = 0.06) -> PrimitiveResult:
    """``push_joint`` for a built scene: no handle site, so the contact point is derived from the part."""
    s0 = drv.steps
    d = drv.data
    body, local = part_point_local(drv, joint)

    def h() -> np.ndarray:
        return d.xpos[body] + d.xmat[body].reshape(3, 3) @ local

    def q() -> float:
        return float(d.joint(joint).qpos[0])

    sign = -1.0 if goal < q() else 1.0
    behind = -sign * joint_motion_direction(drv.model, d, joint, h())
    if not (drv.place_base_near(h(), side=behind) or drv.place_base_near(h())):
        return PrimitiveResult(False, 0, f"no collision-free base pose near {joint}")
    for extra in (0.15, 0.0):
        v = sign * joint_motion_direction(drv.model, d, joint, h())
        drv.goto(h() - (standoff + extra) * v, max_steps=200, tol=0.02)
    while drv.steps - s0 < max_steps and abs(q() - goal) > tol and sign * (goal - q()) > 0:
        v = sign * joint_motion_direction(drv.model, d, joint, h())
        drv.goto(h() + 0.06 * v, max_steps=1, tol=0.0)
    for _ in range(15):  # keep pressing a moment so the part settles instead of bouncing back
        v = sign * joint_motion_direction(drv.model, d, joint, h())
        drv.goto(h() + 0.02 * v, max_steps=1, tol=0.0)
    ok = abs(q() - goal) <= tol or sign * (goal - q()) <= 0
    back = drv.site - 0.12 * sign * joint_motion_direction(drv.model, d, joint, h())
    drv.dp, dp = 0.004, drv.dp  # retreat slowly: a fast pull-back drags a light door with it
    drv.goto(back, max_steps=60)
    drv.dp = dp
    return PrimitiveResult(ok, drv.steps - s0, f"{joint} = {q():.3f} (goal {goal:.3f})")
