"""Close-a-cabinet-door env on the test scene: the SAC benchmark task and the SAC test task.

Test and benchmark support, not part of the package: the SAC tests and ``benchmarks/bench_sac.py``
train on it (:func:`make_door_env`, ``gym.make`` of ``DOOR_ENV_ID``). The paper's action through
``Agent.apply_action``: 6-D end-effector delta (translation, axis-angle rotation, the agent's step
size) plus suction; episodes of 100 steps (the registration's TimeLimit), frameskip 2. The cup
follows a mocap target in the agent's ``"ee_delta_pose"`` control mode (arm servos limp; gravity
compensation holds the arm), so a step is just physics.
The reward is a RewardSpec evaluated on the state dict, exactly as for scene sub-tasks; success is
the door within ``closed_tol`` of closed (the knowledge base's ``joint closed`` check).

Why the start state and observation look the way they do: RoboGen-style sub-tasks start where the
previous primitive left the robot, i.e. with the cup already in front of the part to act on. Starting
from the arm's home pose instead made SAC spend its whole small budget exploring free space (0 %
success after 4000 steps). With ``near_start`` the cup begins a few cm outside the open door's handle
(door opening and cup position drawn from ``np_random``), and the observation is compact and
task-relative (cup and handle relative to the hinge, their difference, the door angle), so the
3x256 networks with lr 3e-4 learn the push in a few thousand steps.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from anomalygen.robot.agent import Agent
from anomalygen.schema import RewardSpec, RewardTerm
from anomalygen.skills.learned.reward import evaluate_spec

# Scales: the door term (~1 rad -> 0) dominates; the distance term keeps the cup on the handle's
# outer side (a few cm -> ~0.3 m when lost) and the action penalty only breaks ties.
DOOR_REWARD = RewardSpec(terms=[
    RewardTerm(kind="joint", joint="cabinet_0:door_hinge", target=0.0, weight=2.0),
    RewardTerm(kind="distance", a="ee", b="cabinet_0:door_push", weight=1.0),
    RewardTerm(kind="action_penalty", weight=0.01),
])
PUSH_OFFSET = 0.04  # the push point: this far outside the handle, along the door's outer normal
HORIZON = 100  # control steps per episode: the registered TimeLimit
DOOR_ENV_ID = "anomalygen/DoorClose-v0"


class DoorCloseEnv(gym.Env):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 20}

    def __init__(self, frameskip: int = 2, open_range=(0.5, 1.3), closed_tol: float = 0.1,
                 reward: RewardSpec = DOOR_REWARD, near_start: bool = True, start_noise: float = 0.02,
                 terminate_on_success: bool = True):
        import mujoco

        from support.door_scene import build

        self._mj = mujoco
        tb = build(door_open=open_range[1])
        self.model, self.data = tb.model, tb.data
        m = self.model
        self._home = mujoco.MjData(m)
        self._home.qpos[:] = self.data.qpos
        self._home.ctrl[:] = self.data.ctrl
        self.frameskip = frameskip
        self.open_range, self.closed_tol, self.reward_spec = open_range, closed_tol, reward
        self.action_space = spaces.Box(-1.0, 1.0, shape=(7,), dtype=np.float32)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(13,), dtype=np.float64)
        self.agent = Agent(m)
        self._site_ee = self.agent.ee_site
        self._site_h = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "cabinet_0:door_handle")
        self._mocap = self.agent.mocap
        self._door_body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "cabinet_0:door")
        self.near_start, self.start_noise, self.terminate_on_success = near_start, start_noise, terminate_on_success
        self._t = 0
        self._action = np.zeros(7)
        self._renderer = None

    @property
    def horizon(self) -> int:
        """Episode length: the TimeLimit's, ``HORIZON`` for an env made bare."""
        from anomalygen.skills.learned.subtask_env import registered_horizon

        return registered_horizon(self, HORIZON)

    # -- state for rewards, success and observations
    @property
    def door(self) -> float:
        return float(self.data.joint("cabinet_0:door_hinge").qpos[0])

    def push_point(self) -> np.ndarray:
        """A point just outside the handle on the door's outer side: where the cup should push."""
        R = self.data.xmat[self._door_body].reshape(3, 3)
        return self.data.site_xpos[self._site_h] - PUSH_OFFSET * R[:, 0]  # local -x is the outer face

    def state(self) -> dict:
        d = self.data
        quat = np.zeros(4)
        self._mj.mju_mat2Quat(quat, d.site_xmat[self._site_ee])
        return {"ee": {"pos": d.site_xpos[self._site_ee].copy(), "quat": quat},
                "objects": {"cabinet_0:door_handle": {"pos": d.site_xpos[self._site_h].copy(), "quat": [1, 0, 0, 0], "size": [0.02] * 3},
                            "cabinet_0:door_push": {"pos": self.push_point(), "quat": [1, 0, 0, 0], "size": [0.02] * 3}},
                "joints": {"cabinet_0:door_hinge": self.door}, "regions": {}, "action": self._action}

    def _obs(self) -> np.ndarray:
        # hinge-relative, ~unit scale (positions in dm): a compact, normalised task observation
        o = self.data.xpos[self._door_body]
        ee, h, p = self.data.site_xpos[self._site_ee], self.data.site_xpos[self._site_h], self.push_point()
        q = self.door
        return np.concatenate([10 * (ee - o), 10 * (h - o), 10 * (p - ee), [q, np.sin(q), np.cos(q)],
                               [self._t / self.horizon]])

    def success(self) -> bool:
        return self.door < self.closed_tol  # at (or pushed just past) the closed stop

    # -- gym API
    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        mj, m, d = self._mj, self.model, self.data
        d.qpos[:] = self._home.qpos
        d.qvel[:] = 0
        d.ctrl[:] = self._home.ctrl
        d.joint("cabinet_0:door_hinge").qpos[0] = self.np_random.uniform(*self.open_range)
        mj.mj_forward(m, d)
        if self.near_start:
            from anomalygen.robot.ik import site_pose, solve_ik

            _, quat = site_pose(m, d, Agent.EE_SITE)
            R = d.xmat[self._door_body].reshape(3, 3)
            start = (self.push_point() - 0.04 * R[:, 0]
                     + self.np_random.uniform(-self.start_noise, self.start_noise, size=3))
            d.qpos[:] = solve_ik(m, d, Agent.EE_SITE, list(Agent.ARM_JOINTS), start, quat, iterations=150).qpos
            mj.mj_forward(m, d)
        self.agent.set_control_mode(d, "ee_delta_pose")
        mj.mj_forward(m, d)
        self._t = 0
        self._action = np.zeros(7)
        return self._obs(), {}

    def step(self, action):
        mj, d = self._mj, self.data
        self._action = self.agent.apply_action(d, action)
        for _ in range(self.frameskip):
            mj.mj_step(self.model, d)
        self._t += 1
        reward = evaluate_spec(self.reward_spec, self.state())
        ok = self.success()
        # ending the episode on success (no bootstrap past it) makes "close it and stop" worth more
        # than any amount of negative shaped reward afterwards; evaluation reads the final flag. The
        # TimeLimit of the registration truncates.
        return self._obs(), reward, ok and self.terminate_on_success, False, {"success": ok, "is_success": ok}

    def render(self):
        if self._renderer is None:
            self._renderer = self._mj.Renderer(self.model, 240, 320)
        self._renderer.update_scene(self.data, "front")
        return self._renderer.render()

    def close(self):
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


def push_joint(env, joint: str, goal: float, point_site: str, *, tol: float = 0.08, max_steps: int = 300,
               standoff: float = 0.05, max_step: float = Agent.STEP_POS):
    """Drive ``joint`` to ``goal`` by pushing at the part point ``point_site`` (the door handle), with the
    cup target moved at most ``max_step`` metres a control step: the push from the joint's kinematics
    alone. A point ``h`` on a part hinged about axis ``a`` through ``p`` moves along ``a x (h - p)``
    when the joint value grows, so the cup first goes to a pre-contact point on the far side of that
    direction (behind the motion), then follows the moving contact point while the joint tracks the
    goal. Returns (success, control steps, detail)."""
    import mujoco

    from anomalygen.skills.geometry import joint_motion_direction

    m, d = env.model, env.data
    sid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, point_site)
    steps = 0

    def q() -> float:
        return float(d.joint(joint).qpos[0])

    def step(target_pos) -> None:
        env.agent.target_towards(d, target_pos, max_step)
        for _ in range(env.frameskip):
            mujoco.mj_step(m, d)

    sign = -1.0 if goal < q() else 1.0  # push against or along the opening direction
    # 1. approach: to the pre-contact point behind the motion, with a lateral stand-off first
    for phase in ("clear", "precontact"):
        for _ in range(max_steps // 3):
            h = d.site_xpos[sid]
            v = sign * joint_motion_direction(m, d, joint, h)
            pre = h - standoff * v + (np.array([0, 0, 0.0]) if phase == "precontact" else -0.15 * v)
            step(pre)
            steps += 1
            if np.linalg.norm(d.site_xpos[env.agent.ee_site] - pre) < 0.02:
                break
    # 2. push: follow the moving point, aiming past it along the motion
    while steps < max_steps and abs(q() - goal) > tol and sign * (goal - q()) > 0:
        h = d.site_xpos[sid]
        v = sign * joint_motion_direction(m, d, joint, h)
        step(h + 0.06 * v)
        steps += 1
    ok = abs(q() - goal) <= tol or sign * (goal - q()) <= 0
    return ok, steps, f"{joint} = {q():.3f} (goal {goal:.3f})"


def make_door_env(**kwargs) -> gym.Env:
    """``gym.make(DOOR_ENV_ID)``: the env inside the TimeLimit its registration sets."""
    return gym.make(DOOR_ENV_ID, **kwargs)


def register() -> None:
    """Register ``anomalygen/DoorClose-v0`` (idempotent); ``gym.make`` adds a TimeLimit at ``HORIZON``."""
    if DOOR_ENV_ID not in gym.registry:
        gym.register(id=DOOR_ENV_ID, entry_point=DoorCloseEnv, max_episode_steps=HORIZON)


register()
