"""A Gymnasium environment for a built scene: end-effector delta actions plus suction.

Action (Box [-1, 1]^7), as in the paper: a delta translation (3) and a delta axis-angle rotation (3,
in the cup frame) of the end effector, scaled by ``max_delta_pos`` / ``max_delta_rot`` per step (the
agent's step size, ``Agent.STEP_POS`` / ``Agent.STEP_ROT``, unless a caller asks otherwise), plus
suction (> 0 on, <= 0 off); :meth:`~anomalygen.robot.agent.Agent.apply_action` maps it, as for every
env. The end effector follows a mocap target through the ``ee_track`` weld (MuJoCo solves it
inside the physics step), so a step costs almost exactly ``frameskip`` raw ``mj_step`` calls: no
Python IK loop. Arm actuators go limp in this mode (gravity compensation keeps the arm up); the base
actuators hold the mobile base where the scene put it.

Observation: a flat float64 vector, the same groups in the same order for every scene (their sizes
follow the scene's objects), named by ``obs_layout``:
``robot_qpos`` and ``robot_qvel`` (the robot's joints, ``Agent.ROBOT_JOINTS`` order), ``ee_pos`` (3)
and ``ee_quat`` (4, w x y z) of the end effector, then every object alike, in ``object_names`` order
(instance names sorted; the scene builder numbers instances by where they stand, so neither the
names nor their order say which object matters): ``object_pos`` (3 per object, its body origin),
``object_quat`` (4 per object), ``object_joints`` (the value of every articulated joint, object by
object, in the asset's joint order), and last ``suction`` (1.0 while something is held).

The env perceives only (``anomalygen.world.perception``): ``env.scene`` is the scene spec with no bindings,
roles, validation report or task id, and ``info`` carries no task words. ``info["is_success"]`` is
there only when a ``success_fn`` is given (the caller's own check, as the skills pass theirs): the env
itself cannot know success without the answer key. The referee's verdict comes from outside.

Suction follows the agent's one grab rule (:meth:`~anomalygen.robot.agent.Agent.grab`): the nearest
graspable body within ``Agent.SUCTION_RANGE`` of the cup is welded at its current relative pose
(rigidly, or by position only for a door, lid or knob); turning suction off releases it.

Hooks: ``reward_fn(env) -> float`` and ``success_fn(env) -> bool`` let the skills stage plug in
RewardSpec/SuccessSpec evaluation (``info["is_success"]`` carries the latter, as SB3 reads it);
``env.graph()`` gives the current SceneGraph. The perceived SceneSpec is ``env.scene``.

Episode length: ``gym.make(ENV_ID, scene_dir=...)`` wraps the env in Gymnasium's ``TimeLimit``
(``max_episode_steps=HORIZON``, set at registration); ``make_env`` returns the bare env, which
truncates after its own ``horizon`` steps without the wrappers' per-step cost.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from anomalygen.robot.agent import Agent

ENV_ID = "anomalygen/Scene-v0"
HORIZON = 100  # control steps per episode


class SceneEnv(gym.Env):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 25}

    def __init__(
        self,
        scene_dir: str | Path,
        frameskip: int = 2,
        horizon: int | None = None,
        *,
        render_mode: str | None = "rgb_array",
        camera: str = "front",
        width: int = 320,
        height: int = 240,
        max_delta_pos: float = Agent.STEP_POS,
        max_delta_rot: float = Agent.STEP_ROT,
        init_noise: float = 0.0,
        reward_fn: Callable[[SceneEnv], float] | None = None,
        success_fn: Callable[[SceneEnv], bool] | None = None,
    ):
        import mujoco

        from anomalygen.world.perception import load_perceived_scene

        self._mj, self._mj_step = mujoco, mujoco.mj_step
        self.scene_dir = Path(scene_dir)
        # ``scene``, not ``spec``: Gymnasium keeps its EnvSpec in ``env.spec`` and ``gym.make`` sets it.
        self.model, self.data, self.scene = load_perceived_scene(self.scene_dir)
        self.frameskip = int(frameskip)
        self.horizon = None if horizon is None else int(horizon)  # None: TimeLimit ends episodes
        self.render_mode, self.camera = render_mode, camera
        self.width, self.height = width, height
        self.max_delta_pos, self.max_delta_rot = float(max_delta_pos), float(max_delta_rot)
        self.init_noise = float(init_noise)
        self.reward_fn, self.success_fn = reward_fn, success_fn
        self._renderer = None

        m = self.model
        name2id = mujoco.mj_name2id
        self.agent = Agent(m)
        self._mocap, self._cup_body = self.agent.mocap, self.agent.cup
        self._ee_site = self.agent.ee_site
        jids = [name2id(m, mujoco.mjtObj.mjOBJ_JOINT, j) for j in Agent.ROBOT_JOINTS]
        self._robot_qpos = np.array([m.jnt_qposadr[j] for j in jids])
        self._robot_qvel = np.array([m.jnt_dofadr[j] for j in jids])
        objects = self.scene.objects  # every object alike, in name order (perception sorts them)
        self.object_names = [o.name for o in objects]
        self._obj_bodies = np.array(
            [name2id(m, mujoco.mjtObj.mjOBJ_BODY, n) for n in self.object_names], dtype=int
        )
        joint_names = [j.name for o in objects for j in o.joint_states]
        self._obj_qpos = np.array(
            [m.jnt_qposadr[name2id(m, mujoco.mjtObj.mjOBJ_JOINT, j)] for j in joint_names], dtype=int
        )

        sizes = {
            "robot_qpos": len(self._robot_qpos),
            "robot_qvel": len(self._robot_qvel),
            "ee_pos": 3,
            "ee_quat": 4,
            "object_pos": 3 * len(self._obj_bodies),
            "object_quat": 4 * len(self._obj_bodies),
            "object_joints": len(self._obj_qpos),
            "suction": 1,
        }
        self.obs_layout: dict[str, slice] = {}
        start = 0
        for key, n in sizes.items():
            self.obs_layout[key] = slice(start, start + n)
            start += n
        self._obs = np.zeros(start)
        # Fast path: the scene compiled observation sensors (world/sensors.py), read in one copy.
        from anomalygen.world.sensors import GROUPS, sensor_items, sensor_layout

        layout = sensor_layout(m)
        self._use_sensors = (
            set(layout) == set(GROUPS)
            and all(layout[g].stop - layout[g].start == sizes[g] for g in GROUPS)
            and sensor_items(m, "object_pos") == self.object_names
            and sensor_items(m, "object_joints") == joint_names
        )  # scenes built before every object had sensors take the slow path
        if self._use_sensors:
            nsens = int(m.nsensordata)
            self.obs_layout = {**layout, "suction": slice(nsens, nsens + 1)}
            start = nsens + 1
            self._obs = np.zeros(start)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(start,), dtype=np.float64)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(7,), dtype=np.float32)
        self._cache_views()
        self.t = 0

    # ------------------------------------------------------------------ gym API
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        from anomalygen.world.graph import reset_to_initial

        super().reset(seed=seed)
        mj, m, d = self._mj, self.model, self.data
        reset_to_initial(m, d)
        if self.init_noise > 0:
            d.qpos[self._robot_qpos] += self.np_random.uniform(
                -self.init_noise, self.init_noise, size=len(self._robot_qpos)
            )
            mj.mj_forward(m, d)
        # Start the mocap target at the cup's pose and switch on tracking (base held in place).
        self.agent.set_control_mode(d, "ee_delta_pose")
        self.t = 0
        return self._observe(), self._info(False)

    def step(self, action):
        # The hot path (benchmarks/bench_env_step.py): each attribute read here costs a share of the
        # frameskip mj_step calls, so the step function and the agent are read once.
        d, agent = self.data, self.agent
        a = agent.apply_action(d, action, dp=self.max_delta_pos, dr=self.max_delta_rot)
        self._mj_step(self.model, d, self.frameskip)
        self.t += 1
        if self._use_sensors:  # inlined _observe fast path; suction off releases, so only 'on' asks
            self._o_sens[:] = self._v_sens
            self._obs[-1] = 0.0 if a[6] <= 0.0 or agent.held(d) is None else 1.0
            obs = self._obs.copy()
        else:
            obs = self._observe()
        reward = float(self.reward_fn(self)) if self.reward_fn is not None else 0.0
        success = bool(self.success_fn(self)) if self.success_fn is not None else False
        truncated = self.horizon is not None and self.t >= self.horizon
        return obs, reward, success, truncated, self._info(success)

    def _info(self, success: bool) -> dict:
        """``is_success`` only from the caller's own check: without one the env cannot know it."""
        return {"is_success": success} if self.success_fn is not None else {}

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        if self._renderer is None:
            from anomalygen.world.render import SceneRenderer

            self._renderer = SceneRenderer(self.model, self.width, self.height)
        return self._renderer.render(self.data, self.camera)

    def close(self):
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    # ------------------------------------------------------------------ helpers
    def _cache_views(self) -> None:
        """Keep numpy views of MjData arrays: each attribute access costs a pybind call per step."""
        d, L, o = self.data, self.obs_layout, self._obs
        self._v_sens = d.sensordata
        self._o_sens = o[:-1]
        self._v_qpos, self._v_qvel, self._v_xpos, self._v_xquat = d.qpos, d.qvel, d.xpos, d.xquat
        self._v_site = d.site_xpos[self._ee_site]
        self._o = {k: o[v] for k, v in L.items()}
        self._o_obj_pos = self._o["object_pos"].reshape(-1, 3)
        self._o_obj_quat = self._o["object_quat"].reshape(-1, 4)
        self._lo = np.zeros(3)
        self._hi = np.zeros(3)

    def _observe(self) -> np.ndarray:
        held = 0.0 if self.agent.held(self.data) is None else 1.0
        if self._use_sensors:
            self._o_sens[:] = self._v_sens
            self._obs[-1] = held
            return self._obs.copy()
        o = self._o
        np.take(self._v_qpos, self._robot_qpos, out=o["robot_qpos"])
        np.take(self._v_qvel, self._robot_qvel, out=o["robot_qvel"])
        o["ee_pos"][:] = self._v_site
        o["ee_quat"][:] = self._v_xquat[self._cup_body]
        o["suction"][0] = held
        np.take(self._v_xpos, self._obj_bodies, axis=0, out=self._o_obj_pos)
        np.take(self._v_xquat, self._obj_bodies, axis=0, out=self._o_obj_quat)
        np.take(self._v_qpos, self._obj_qpos, out=o["object_joints"])
        return self._obs.copy()

    @property
    def held(self) -> str | None:
        """Name of the object held by suction, if any."""
        return self.agent.held(self.data)

    def graph(self):
        """The SceneGraph of the current state (for success predicates)."""
        from anomalygen.world.graph import scene_graph

        self._mj.mj_forward(self.model, self.data)
        return scene_graph(self.model, self.data, self.scene)


def make_env(scene_dir, frameskip: int = 2, horizon: int = HORIZON, **kwargs) -> SceneEnv:
    """The env for a built scene folder, unwrapped (no checker wrappers: they would add step cost)."""
    return SceneEnv(scene_dir, frameskip=frameskip, horizon=horizon, **kwargs)


def register() -> None:
    """Register ``anomalygen/Scene-v0`` with Gymnasium (idempotent): ``gym.make(ENV_ID, scene_dir=...)``."""
    if ENV_ID not in gym.registry:
        gym.register(id=ENV_ID, entry_point="anomalygen.world.env:SceneEnv", max_episode_steps=HORIZON)


register()
