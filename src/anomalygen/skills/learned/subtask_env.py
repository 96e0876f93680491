"""A Gymnasium env for one SAC sub-task of a plan, on the loaded scene, from the state it starts in.

RoboGen-style: a learned sub-task starts where the plan's previous steps left the robot, so the env
is built from a full physics snapshot (``mj_getState(..., mjSTATE_INTEGRATION)``: qpos, qvel, ctrl,
mocap pose, active welds, ...) of the :class:`~anomalygen.robot.driver.Driver`'s data, and every
``reset`` restores it (plus +-2 cm noise on the end-effector target, drawn from ``np_random``). The
env owns a copy of the model and its own MjData: suction rewrites the weld pose in ``model.eq_data``,
and training must never touch the scene the Driver runs on.

Paper settings, as in the SAC door benchmark's env: 7-D action (the agent's step size: 3 cm per step
cup translation, 0.1 rad per step rotation in the cup frame; suction on when the last entry is > 0),
episodes of ``HORIZON`` = 100 steps, frameskip 2. The env is registered as ``SUBTASK_ENV_ID`` with
``max_episode_steps=HORIZON``: Gymnasium's ``TimeLimit`` ends episodes (:func:`make_subtask_env`), the
env itself never truncates. :meth:`~anomalygen.robot.agent.Agent.apply_action` is the one action
mapping (every env and the Driver share it); ``run_sac_subtask`` replays the trained policy on the
Driver's own data through it, so training and the recorded rollout behave the same.

Reward = ``reward.evaluate_spec(sub_task.reward, state)`` over the state dict of ``reward.py``
(objects by instance name: AABB centre, root-body quaternion, AABB extents; links
``<instance>:<body>`` and sites likewise; ``regions`` are the AABBs of the ``inside`` terms'
containers). The observation is built from the same readout, only for the names the reward mentions.

Success is the sub-task's SuccessSpec on ``scene_graph`` when it has predicates, else the goal terms
of its reward (joint within 5 % of its range of the target, as ``joint_closed`` counts closed; object
above a ``lifted`` height; point inside an ``inside`` box), checked every step (microseconds).
Checking the predicates builds a scene graph, which costs about as much as the rest of a step, so
they are checked every ``success_every`` = 4 steps and on the last one: a few % of training time,
and an episode runs at most 3 steps past success (the figures are in docs/learn.md).
"""

from __future__ import annotations

import copy

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from anomalygen.mjgeom import geom_world_aabbs
from anomalygen.robot.agent import Agent
from anomalygen.robot.frames import subtree_geoms
from anomalygen.schema import CLOSED_TOL, RewardSpec, SceneSpec, SubTask
from anomalygen.skills.learned.reward import evaluate_spec
from anomalygen.world.graph import scene_graph

SUBTASK_ENV_ID = "anomalygen/SubTask-v0"
HORIZON = 100  # control steps per episode: the registered TimeLimit
FRAMESKIP = 2
START_NOISE = 0.02  # m: +- noise on the end-effector target at reset
SUCCESS_EVERY = 4
POS_SCALE = 10.0  # positions in the observation are in dm (~unit scale for the networks)


def registered_horizon(env: gym.Env, default: int) -> int:
    """The episode length of an env that leaves truncation to Gymnasium: its TimeLimit's
    ``max_episode_steps`` (``gym.make`` puts the registration's into ``env.spec``), ``default`` for an
    env made bare (whose episodes then run until terminated)."""
    limit = env.spec.max_episode_steps if env.spec is not None else None
    return int(limit) if limit else default


def _collision_geoms(model, body: int) -> np.ndarray:
    """Ids of the geoms of ``body`` and its descendants, planes left out (they have no finite box)."""
    return np.flatnonzero(subtree_geoms(model, body) & (model.geom_type != 0))


class SubTaskReadout:
    """The sub-task's view of any (model, data) of the scene: state dict, observation, success.

    Separate from the env so the rollout on the Driver's data reads exactly what training read.
    Names in the reward may be role variables (``$hazard``); they are resolved through ``bindings``
    and the state dict carries them under both spellings, so ``evaluate_spec(sub_task.reward, state)``
    works on the spec as written.
    """

    def __init__(self, model, spec: SceneSpec, sub_task: SubTask, bindings: dict[str, str]):
        import mujoco

        reward = sub_task.reward
        if reward is None or (reward.mode == "spec" and not reward.terms) or (reward.mode == "code" and not reward.code):
            raise ValueError(f"sub-task {sub_task.id} has no reward terms or reward code to learn from")
        self.spec, self.sub_task, self.bindings = spec, sub_task, dict(bindings)
        self.reward: RewardSpec = reward
        # Reward code (mode "code") is untrusted: it runs in the sandbox's limited subprocess.
        self._code = None
        if reward.mode == "code":
            from anomalygen.skills.learned.sandbox import SandboxedReward

            self._code = SandboxedReward(reward.code)
        self.agent = Agent(model)
        self._mj = mujoco
        # every spec object: (name, root body, geom ids); referenced links and sites added below
        self._boxes: dict[str, tuple[int, np.ndarray]] = {}
        for o in spec.objects:
            b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, o.name)
            if b >= 0:
                self._boxes[o.name] = (b, _collision_geoms(model, b))
        self._sites: dict[str, int] = {}
        self._alias: dict[str, str] = {}  # name as written in the spec -> resolved name
        points: list[str | tuple] = []
        joints: list[str] = []
        self._upright: list[str] = []
        self._regions: list[str] = []
        for t in self.reward.terms:
            if t.kind == "joint":
                jn = self._resolve(model, t.joint or t.a, kind="joint")
                joints.append(jn)
                continue
            for ref in (t.a, t.b):
                if ref is not None and ref != "ee":
                    points.append(self._resolve(model, ref))
            if t.kind == "distance" and t.b is None and isinstance(t.target, list):
                points.append(tuple(float(v) for v in t.target))
            if t.kind == "upright":
                self._upright.append(self._resolve(model, t.a))
            if t.kind == "inside":
                self._regions.append(self._resolve(model, t.b))
        self.points = list(dict.fromkeys(points))
        self.joints = list(dict.fromkeys(joints))
        self._upright = list(dict.fromkeys(self._upright))
        self._regions = list(dict.fromkeys(self._regions))
        self.obs_dim = 3 + 4 + 3 * len(self.points) + len(self.joints) + 4 * len(self._upright) + 2
        self.joint_tol = {}
        for j in self.joints:
            lo, hi = model.joint(j).range
            self.joint_tol[j] = CLOSED_TOL * max(float(hi - lo), 1e-6) if hi > lo else 0.05

    def reward_of(self, state: dict) -> float:
        """The sub-task's reward for a state: its RewardSpec, or its reward code in the sandbox."""
        return self._code(state) if self._code is not None else evaluate_spec(self.reward, state)

    def close(self) -> None:
        if self._code is not None:
            self._code.close()

    def resolved(self, ref: str) -> str:
        """The scene name a reward reference stands for (role variables resolved)."""
        return self._alias.get(ref, ref)

    def _resolve(self, model, ref: str | None, *, kind: str = "point") -> str:
        if ref is None:
            raise ValueError(f"sub-task {self.sub_task.id}: a reward term lacks its object/joint name")
        name = self.bindings.get(ref, ref) if ref.startswith("$") else ref
        if name != ref:
            self._alias[ref] = name
        mj = self._mj
        if kind == "joint":
            if mj.mj_name2id(model, mj.mjtObj.mjOBJ_JOINT, name) < 0:
                raise ValueError(f"sub-task {self.sub_task.id}: no joint {name!r} in the scene")
            return name
        if name in self._boxes or name in self._sites:
            return name
        b = mj.mj_name2id(model, mj.mjtObj.mjOBJ_BODY, name)
        if b >= 0:
            self._boxes[name] = (b, _collision_geoms(model, b))
            return name
        s = mj.mj_name2id(model, mj.mjtObj.mjOBJ_SITE, name)
        if s >= 0:
            self._sites[name] = s
            return name
        j = mj.mj_name2id(model, mj.mjtObj.mjOBJ_JOINT, name)
        if j >= 0:  # a joint stands for the part it moves (a knob: the planner knows joints, not bodies)
            b = int(model.jnt_bodyid[j])
            self._boxes[name] = (b, _collision_geoms(model, b))
            return name
        raise ValueError(f"sub-task {self.sub_task.id}: reward names {ref!r}, which is no object, link, site or joint")

    # ------------------------------------------------------------------ readout
    def state(self, model, data, action=None) -> dict:
        """The reward.py state dict (call after mj_forward / mj_step)."""

        glo, ghi = geom_world_aabbs(model, data)
        quat = np.zeros(4)
        self._mj.mju_mat2Quat(quat, data.site_xmat[self.agent.cup_site])
        objects: dict[str, dict] = {}
        for name, (body, geoms) in self._boxes.items():
            if len(geoms):
                lo, hi = glo[geoms].min(axis=0), ghi[geoms].max(axis=0)
            else:
                lo = hi = data.xpos[body].copy()
            objects[name] = {"pos": (lo + hi) / 2, "quat": data.xquat[body].copy(), "size": hi - lo}
        for name, sid in self._sites.items():
            objects[name] = {"pos": data.site_xpos[sid].copy(), "quat": np.array([1.0, 0, 0, 0]), "size": np.full(3, 0.02)}
        regions = {}
        for name in self._regions:
            o = objects[name]
            regions[name] = {"lo": o["pos"] - o["size"] / 2, "hi": o["pos"] + o["size"] / 2}
        joints = {j: float(data.joint(j).qpos[0]) for j in self.joints}
        for ref, name in self._alias.items():
            for table in (objects, regions, joints):
                if name in table:
                    table[ref] = table[name]
        return {"ee": {"pos": data.site_xpos[self.agent.cup_site].copy(), "quat": quat},
                "suction": 1.0 if self.agent.held(data) is not None else 0.0,
                "objects": objects, "joints": joints, "regions": regions,
                "action": np.zeros(7) if action is None else np.asarray(action, dtype=float)}

    def observation(self, state: dict, ee0: np.ndarray, t: int, horizon: int) -> np.ndarray:
        """Cup pose (position relative to its start), referenced points relative to the cup, joint
        values, upright objects' quaternions, suction flag, time fraction."""
        ee = np.asarray(state["ee"]["pos"], dtype=float)
        q = np.asarray(state["ee"]["quat"], dtype=float)
        parts = [POS_SCALE * (ee - ee0), q if q[0] >= 0 else -q]
        for p in self.points:
            pos = np.asarray(p, dtype=float) if isinstance(p, tuple) else np.asarray(state["objects"][p]["pos"])
            parts.append(POS_SCALE * (pos - ee))
        parts.append(np.array([state["joints"][j] for j in self.joints], dtype=float))
        for name in self._upright:
            parts.append(np.asarray(state["objects"][name]["quat"], dtype=float))
        parts.append(np.array([state["suction"], t / horizon]))
        return np.concatenate(parts).astype(np.float64)

    def has_predicates(self) -> bool:
        return bool(self.sub_task.success.predicates)

    def success(self, model, data, state: dict) -> tuple[bool, str]:
        """(success, why): the SuccessSpec on the scene graph, else the reward's goal terms."""
        if self.has_predicates():
            from anomalygen.knowledge.predicates import evaluate_all

            res = evaluate_all(list(self.sub_task.success.predicates), scene_graph(model, data, self.spec), self.bindings)
            return all(r.holds for r in res), "; ".join(f"{r.call.name}: {'yes' if r.holds else 'no'}" for r in res)
        return self.goal_terms_hold(state)

    def goal_terms_hold(self, state: dict) -> tuple[bool, str]:
        from anomalygen.skills.learned.reward import box_of, position_of

        checks, why = [], []
        for t in self.reward.terms:
            if t.kind == "joint":
                j = self.resolved(t.joint or t.a)
                checks.append(abs(state["joints"][j] - float(t.target)) <= self.joint_tol[j])
            elif t.kind == "lifted":
                checks.append(position_of(state, t.a)[2] >= float(t.target) - 0.01)
            elif t.kind == "inside":
                lo, hi = box_of(state, t.b)
                p = position_of(state, t.a)
                checks.append(bool(np.all(p >= lo) and np.all(p <= hi)))
            else:
                continue
            why.append(f"{t.kind} {t.joint or t.a}: {'yes' if checks[-1] else 'no'}")
        if not checks:
            return False, "no success test (no predicates, no joint/lifted/inside reward term)"
        return all(checks), "; ".join(why)

    def joint_summary(self, state: dict) -> str:
        return ", ".join(f"{j.split(':')[-1]} = {state['joints'][j]:.3f}" for j in self.joints)


class SubTaskEnv(gym.Env):
    """One sub-task on the scene, from a snapshot; see the module docstring for the contract.
    Make it with :func:`make_subtask_env` (``gym.make``), which adds the episode's TimeLimit."""

    metadata = {"render_modes": []}

    def __init__(self, model, snapshot: np.ndarray, spec: SceneSpec, sub_task: SubTask,
                 bindings: dict[str, str] | None = None, *, frameskip: int = FRAMESKIP,
                 start_noise: float = START_NOISE, success_every: int = SUCCESS_EVERY):
        import mujoco

        self._mj = mujoco
        self.model = copy.deepcopy(model)  # suction writes eq_data: keep the caller's model untouched
        self.data = mujoco.MjData(self.model)
        self.snapshot = np.array(snapshot, dtype=float, copy=True)
        self._eq_data0 = self.model.eq_data.copy()
        self.readout = SubTaskReadout(self.model, spec, sub_task, bindings or {})
        self.frameskip = int(frameskip)
        self.start_noise, self.success_every = float(start_noise), max(1, int(success_every))
        self.action_space = spaces.Box(-1.0, 1.0, shape=(7,), dtype=np.float32)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(self.readout.obs_dim,), dtype=np.float64)
        self._restore()
        self._ee0 = self.data.site_xpos[self.readout.agent.cup_site].copy()
        self._t = 0
        self._state = self.readout.state(self.model, self.data)
        self.readout.reward_of(self._state)  # dry run: bad reward code fails here, before any training

    @property
    def horizon(self) -> int:
        """Episode length (:func:`registered_horizon`); the observation's time fraction and the last
        step's success check read it."""
        return registered_horizon(self, HORIZON)

    def close(self) -> None:
        self.readout.close()

    def _restore(self) -> None:
        mj = self._mj
        self.model.eq_data[:] = self._eq_data0
        mj.mj_setState(self.model, self.data, self.snapshot, mj.mjtState.mjSTATE_INTEGRATION)
        mj.mj_forward(self.model, self.data)

    def state(self) -> dict:
        return self._state

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self._restore()
        if self.start_noise > 0:
            self.data.mocap_pos[self.readout.agent.mocap] += self.np_random.uniform(-self.start_noise, self.start_noise, 3)
            self._mj.mj_forward(self.model, self.data)
        self._t = 0
        self._state = self.readout.state(self.model, self.data)
        return self.readout.observation(self._state, self._ee0, 0, self.horizon), {}

    def step(self, action):
        def advance() -> None:
            for _ in range(self.frameskip):
                self._mj.mj_step(self.model, self.data)

        self._t += 1
        self._state, reward, ok, _ = control_step(self.readout, self.model, self.data, action, self._t, advance,
                                                  horizon=self.horizon, success_every=self.success_every)
        obs = self.readout.observation(self._state, self._ee0, self._t, self.horizon)
        return obs, reward, ok, False, {"success": ok, "is_success": ok}


def control_step(readout: SubTaskReadout, model, data, action, t: int, advance, *, horizon: int = HORIZON,
                 success_every: int = SUCCESS_EVERY) -> tuple[dict, float, bool, str]:
    """One control step, shared by the env and the Driver rollout: apply the action, ``advance()``
    the physics (frameskip steps), read the state; success is checked on the schedule described in
    the module docstring. ``t`` counts this step (1-based). Returns (state, reward, success, why)."""
    a = readout.agent.apply_action(data, action)
    advance()
    state = readout.state(model, data, a)
    reward = readout.reward_of(state)
    ok, why = False, ""
    if t >= horizon or t % success_every == 0 or not readout.has_predicates():
        ok, why = readout.success(model, data, state)
    return state, reward, ok, why


def make_subtask_env(model, snapshot: np.ndarray, spec: SceneSpec, sub_task: SubTask,
                     bindings: dict[str, str] | None = None, **kwargs) -> gym.Env:
    """``gym.make(SUBTASK_ENV_ID, ...)``: the env inside the TimeLimit its registration sets."""
    return gym.make(SUBTASK_ENV_ID, model=model, snapshot=snapshot, spec=spec, sub_task=sub_task,
                    bindings=bindings, **kwargs)


def register() -> None:
    """Register ``anomalygen/SubTask-v0`` (idempotent), episodes of ``HORIZON`` steps."""
    if SUBTASK_ENV_ID not in gym.registry:
        gym.register(id=SUBTASK_ENV_ID, entry_point="anomalygen.skills.learned.subtask_env:SubTaskEnv",
                     max_episode_steps=HORIZON)


register()
