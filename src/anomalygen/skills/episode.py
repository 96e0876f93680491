"""One execution of plans on one loaded scene: what every skill runs with (:class:`Episode`).

Skills get the episode, not a loose set of arguments: the simulator (model, data, and the perceived
scene spec: no bindings, no roles, so a skill cannot see the answer key), the robot (``agent``, and
the ``driver`` that moves it and counts control steps), what skills remember between sub-tasks
(:class:`SkillMemory`), the budget (:class:`EpisodeBudget`), the video recorder, and the settings of
learned skills.
One episode runs the plan and, with the learn stage's recheck, the repair plan after it, so the
memory of what the first opened is there when the second shuts it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from anomalygen.robot.driver import Driver
from anomalygen.robot.motion import restart_seed_sequence
from anomalygen.schema import Plan, SceneSpec
from anomalygen.world.graph import scene_graph


@dataclass
class SkillMemory:
    """What skills remember between sub-tasks of one episode."""

    opened: dict[str, list[str]] = field(default_factory=dict)  # container -> joints opened to put something in
    # container -> (lo, hi, outward normal) of the compartment behind its opened door
    compartments: dict[str, tuple] = field(default_factory=dict)
    # object -> (support, x/y offset of where it came to rest from the spot aimed at): a set-down that
    # is tried again aims that much the other way
    set_down_error: dict[str, tuple[str, np.ndarray]] = field(default_factory=dict)
    # container -> its root body's position when the compartment was measured: a light safe on the
    # floor slides while its door is pulled, and the compartment moves with it
    compartment_anchor: dict[str, np.ndarray] = field(default_factory=dict)


#: Control steps after which an episode starts no further sub-task or retry. A count, not seconds: a
#: wall-clock budget (600 s until now) cut items short on a busy machine that an idle one finished, so
#: the outcome depended on the load. The longest normal episodes run about 12,000 steps (a container
#: opened, emptied and shut, with retries); an idle core runs 50,000 in a few minutes. Only a runaway
#: episode reaches it.
EPISODE_MAX_STEPS = 50_000
#: Wall-clock safety net for one episode, seconds: three hours, several times what the longest
#: normal episodes took on the shared, heavily loaded 2-core development machine (~20 minutes). It
#: only ends an episode that hangs; reaching it makes the result depend on the machine.
EPISODE_WALL_CAP_S = 3 * 3600.0
REST_SPEED = 0.05  # m/s: a loose object slower than this has come to rest (the referee settles to the same)
REST_MAX_STEPS = 100  # control steps (1 s simulated) a step's check waits at most for things to stop moving
FREE = 0  # mujoco.mjtJoint.mjJNT_FREE


@dataclass
class EpisodeBudget:
    """When an episode stops starting sub-tasks: after ``max_steps`` control steps, or (safety net)
    ``seconds`` of wall time counted from ``start`` (a ``perf_counter`` reading)."""

    max_steps: int = EPISODE_MAX_STEPS
    seconds: float = EPISODE_WALL_CAP_S
    start: float = field(default_factory=time.perf_counter)

    def elapsed(self) -> float:
        """Wall seconds since ``start``: for timings only, never for a decision short of the safety net."""
        return time.perf_counter() - self.start

    def spent(self, steps: int) -> str:
        """Why the episode should start nothing more after ``steps`` control steps ("" while it may)."""
        if steps >= self.max_steps:
            return f"the episode's {self.max_steps} control steps are spent"
        if self.elapsed() > self.seconds:
            return f"the episode's {self.seconds:g} s wall-clock safety net is spent"
        return ""


@dataclass
class LearningSettings:
    """How learned skills train on the spot (``learn.sac_steps``, ``learn.reward_mode``, ``learn.n_envs``)."""

    sac_steps: int = 0
    reward_mode: str = "spec"
    n_envs: int = 1


class Episode:
    """The scene, the robot, the skills' memory, the budget and the video of one execution."""

    def __init__(self, model, data, spec: SceneSpec, *, seed: int = 0, rng: np.random.Generator | None = None,
                 plan: Plan | None = None, budget: EpisodeBudget | None = None,
                 learning: LearningSettings | None = None, video=None):
        self.model, self.data, self.spec = model, data, spec
        self.seed = int(seed)
        self.plan = plan  # the plan being run: its bindings resolve role variables in sub-task params
        self.budget = budget or EpisodeBudget()
        self.learning = learning or LearningSettings()
        self.video = video  # a VideoRecorder (skills/video.py) fed every control step, or None
        on_step = (lambda drv: video.capture(drv.data)) if video is not None else None
        self.driver = Driver(model, data, rng=rng, on_step=on_step)
        restart_seed_sequence(self.driver.plan_seed)  # its plans depend on its seed, not on the process's past
        self.agent = self.driver.agent
        self.memory = SkillMemory()

    @property
    def bindings(self) -> dict[str, str]:
        return dict(self.plan.bindings) if self.plan is not None else {}

    @property
    def steps(self) -> int:
        """Control steps the robot has taken in this episode."""
        return self.driver.steps

    def settle(self, n: int) -> None:
        self.driver.settle(n)

    def come_to_rest(self, max_steps: int = REST_MAX_STEPS) -> None:
        """Step until no loose object moves faster than REST_SPEED, at most ``max_steps`` control
        steps: a plate set down on its rim stands for a moment before it falls off the shelf, and a
        check made in that moment passes on a state that does not last."""
        for _ in range(max_steps):
            if self._fastest() <= REST_SPEED:
                return
            self.driver.step()

    def _fastest(self) -> float:
        """Speed (m/s) of the fastest free-standing object of the scene."""
        m, d = self.model, self.data
        speed = 0.0
        for o in self.spec.objects:
            j = int(m.body_jntadr[self.driver.body_id(o.name)])
            if o.fixed or j < 0 or m.jnt_type[j] != FREE:
                continue
            a = int(m.jnt_dofadr[j])
            speed = max(speed, float(np.linalg.norm(d.qvel[a:a + 3])))
        return speed

    def graph(self):
        """The scene graph of the current state, as the robot perceives it."""

        return scene_graph(self.model, self.data, self.spec)
