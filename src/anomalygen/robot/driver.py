"""The Driver: the control loop every skill runs through, on one loaded scene's model and data.

The arm is driven in the agent's ``"ee_delta_pose"`` control mode: the cup follows the mocap target,
which is moved along straight interpolated waypoints at most ``dp`` metres per control step
(``frameskip`` physics steps each), or along joint paths planned by :mod:`~anomalygen.robot.arm_motion`.
The mobile base is placed kinematically: a collision-free pose facing the target at arm's reach (the
agent's reach envelope, :mod:`~anomalygen.robot.reach`) is chosen from a fixed ring of candidates
(deterministic; no base path planning), and a held object is carried rigidly with it. Given the seed,
every run is identical. The Driver moves the robot and counts steps; what a skill remembers between
sub-tasks lives in :class:`~anomalygen.skills.episode.Episode`, scene queries in
:mod:`~anomalygen.skills.geometry`, the skills themselves in :mod:`anomalygen.skills`.
"""

from __future__ import annotations

import numpy as np

from anomalygen.mjgeom import FLOOR_GEOM, geom_world_aabbs
from anomalygen.robot.agent import Agent

REACH = Agent.REACH
LIFT_LEVELS = (0.0, Agent.LIFT_MAX / 2, Agent.LIFT_MAX)  # torso lift heights tried, lowest first


class Driver:
    """Moves the suction cup and the base of the robot in one model; counts control steps, calls ``on_step``."""

    def __init__(self, model, data, *, frameskip: int = 5, dp: float = 0.012, on_step=None,
                 rng: np.random.Generator | None = None, planned_motion: bool = True):
        import mujoco

        self.model, self.data = model, data
        self.frameskip, self.dp, self.on_step = int(frameskip), float(dp), on_step
        self.steps = 0
        self.planned_motion = planned_motion  # reach pre-contact poses by IK + OMPL paths
        self.reaches = True  # did the last base placement satisfy its reach poses?
        self.plan_seed = int(rng.integers(2**31)) if rng is not None else 0
        # The seed only turns the ring of candidate base poses, so seeds try different approach sides.
        self.ring_offset = float(rng.uniform(0.0, 2 * np.pi / REACH.headings)) if rng is not None else 0.0
        self.agent = Agent(model)
        self.agent.set_control_mode(data, "ee_delta_pose")
        self._mocap = self.agent.mocap
        self._cup, self._site_ee = self.agent.cup, self.agent.cup_site
        mujoco.mj_forward(model, data)
        r = data.xmat[self._cup].reshape(3, 3)
        self._site_local = r.T @ (data.site_xpos[self._site_ee] - data.xpos[self._cup])
        self._robot_geoms = set(self.agent.geoms.tolist())
        self._floor = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, FLOOR_GEOM)

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
        from anomalygen.robot.arm_motion import move_arm_planned

        return any(move_arm_planned(self, g, quat, seed=self.plan_seed, ik_attempts=3).ok for g in goals)

    def straighten_wrist(self, lift: float = 0.0, lift_steps: int = 40) -> None:
        """If a pull or side grasp left the cup sideways, rise by ``lift`` and plan back to the home
        configuration: a straight cup-down move from there winds the wrist into the furniture."""
        if not self.planned_motion or self.cup_down():
            return
        from anomalygen.robot.arm_motion import rehome

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
            self.agent.target_towards(d, target - rq.reshape(3, 3) @ self._site_local, self.dp)
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

        mask = self.agent.subtree_geoms(self.body_id(name))
        lo, hi = geom_world_aabbs(self.model, self.data)
        coll = mask & (self.model.geom_contype | self.model.geom_conaffinity).astype(bool)
        use = coll if coll.any() else mask
        return lo[use].min(axis=0), hi[use].max(axis=0)

    def _robot_in_collision(self) -> bool:
        """Robot or the object it holds penetrating the world (the floor under the base excepted)."""

        d = self.data
        held = self.held
        carried = self.agent.subtree_geoms(self.body_id(held)) if held is not None else None
        for i in range(d.ncon):
            g1, g2 = int(d.contact.geom1[i]), int(d.contact.geom2[i])
            r1 = g1 in self._robot_geoms or (carried is not None and carried[g1])
            r2 = g2 in self._robot_geoms or (carried is not None and carried[g2])
            if r1 != r2 and self._floor not in (g1, g2) and d.contact.dist[i] < -0.002:
                return True
        return False

    def _in_body(self, geom: int, name: str) -> bool:
        return bool(self.agent.subtree_geoms(self.body_id(name))[geom])

    @property
    def held(self) -> str | None:
        return self.agent.held(self.data)

    # ---------------------------------------------------------------- base
    def place_base_near(self, point, *, reach=REACH.ring, side=None, tuck: bool = True, reach_poses=()) -> bool:
        """Put the base at a collision-free pose facing ``point`` at arm's reach (kinematic move).

        The base stays where it is when ``point`` lies in the reach envelope's ``stay_band`` and it
        faces it. Otherwise candidates: rings of ``REACH.headings`` headings at each distance in
        ``reach`` (the envelope's ``ring``), tried nearest-to-current first;
        with ``side`` (a horizontal direction from the point), only poses on that side (within 70 deg).
        With ``reach_poses`` ((pos, quat) pairs) a pose must also let the arm reach each of them by IK
        (else the first free pose is taken); the torso lift stays down unless only a raised arm
        reaches them (a lid on a box on a counter), then it rises in steps. A held object is carried
        rigidly with the base. Returns False (base unchanged) if none is free.
        """
        import mujoco

        m, d = self.model, self.data
        p = np.asarray(point, dtype=float)
        cur = self.agent.base_pose(d)
        sd = None if side is None else np.asarray(side, dtype=float)[:2] / (np.linalg.norm(np.asarray(side)[:2]) + 1e-9)
        on_side = (lambda b: True) if sd is None else (
            lambda b: float(np.dot(b - p[:2], sd)) > 0.34 * float(np.linalg.norm(b - p[:2])))
        lift0 = self.agent.lift()
        # stay put only at a comfortable distance: 0.33 m from a spot low in a bin the IK still says
        # yes, but the wrist tips before the cup gets down and the base already leans on the bin
        if (REACH.stay_band[0] <= np.hypot(*(p[:2] - cur[:2])) < REACH.stay_band[1] and self._facing(cur, p) and on_side(cur[:2])
                and (lift0 < 0.01 or reach_poses) and self._reaches(reach_poses)):
            return True
        saved = (d.qpos.copy(), d.qvel.copy(), d.mocap_pos.copy(), d.mocap_quat.copy())
        held = self.held
        hb = self.body_id(held) if held else -1
        hq = m.jnt_qposadr[m.body_jntadr[hb]] if held and m.body_jntadr[hb] >= 0 else -1
        for lift in LIFT_LEVELS if reach_poses else LIFT_LEVELS[:1]:
            for r in reach:
                angles = self.ring_offset + np.linspace(0, 2 * np.pi, REACH.headings, endpoint=False)
                cands = [b for b in (p[:2] + r * np.array([np.cos(a), np.sin(a)]) for a in angles) if on_side(b)]
                cands.sort(key=lambda b: float(np.hypot(*(b - cur[:2]))))
                for b in cands:
                    yaw = float(np.arctan2(p[1] - b[1], p[0] - b[0]))
                    self._move_base_rigid(np.array([*cur, lift0]), np.array([b[0], b[1], yaw, lift]), saved, hq)
                    mujoco.mj_forward(m, d)
                    if not self._robot_in_collision() and self._reaches(reach_poses):
                        for j, v in zip(Agent.BASE_JOINTS, (b[0], b[1], yaw), strict=True):
                            d.actuator(j).ctrl[0] = v
                        d.qvel[:] = 0.0
                        self.settle(10)
                        self.reaches = True
                        return True
        d.qpos[:], d.qvel[:], d.mocap_pos[:], d.mocap_quat[:] = saved
        self.agent.set_lift(d, lift0)
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
        from anomalygen.robot.ik import solve_ik
        home = np.asarray(Agent.HOME_ARM, dtype=float)
        for pos, quat in poses:
            r = solve_ik(self.model, self.data, Agent.CUP_SITE, Agent.ARM_JOINTS, pos, quat, q_init=home,
                         iterations=150)
            if not r.success:
                return False
        return True

    def tuck(self) -> bool:
        """Bring the cup (and anything held) in close above the base, cup down, before a base move."""
        from anomalygen.robot.ik import quat_z_to
        d = self.data
        x, y, yaw = (float(d.joint(j).qpos[0]) for j in Agent.BASE_JOINTS)
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

        d = self.data
        qpos0, _, mpos0, mquat0 = saved
        d.qpos[:] = qpos0
        for j, v in zip(Agent.BASE_JOINTS, new[:3], strict=True):
            d.joint(j).qpos[0] = v
        self.agent.set_lift(d, new[3])
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
