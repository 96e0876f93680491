"""One execution of plans on one loaded scene: what every skill runs with (:class:`Episode`).

Skills get the episode, not a loose set of arguments: the simulator (model, data, and the perceived
scene spec: no bindings, no roles, so a skill cannot see the answer key), the robot (``agent``, and
the ``driver`` that moves it and counts control steps), what skills remember between sub-tasks
(:class:`SkillMemory`), the wall-clock budget, the video recorder, and the settings of learned skills.
One episode runs the plan and, with the learn stage's recheck, the repair plan after it, so the
memory of what the first opened is there when the second shuts it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from anomalygen.robot.driver import Driver
from anomalygen.schema import Plan, SceneSpec


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


@dataclass
class TimeBudget:
    """Wall-clock seconds an episode may spend, counted from ``start`` (a ``perf_counter`` reading)."""

    seconds: float = 600.0
    start: float = field(default_factory=time.perf_counter)

    def elapsed(self) -> float:
        return time.perf_counter() - self.start

    def spent(self) -> bool:
        return self.elapsed() > self.seconds


@dataclass
class LearningSettings:
    """How learned skills train on the spot (``learn.sac_steps``, ``learn.reward_mode``, ``learn.n_envs``)."""

    sac_steps: int = 0
    reward_mode: str = "spec"
    n_envs: int = 1


class Episode:
    """The scene, the robot, the skills' memory, the budget and the video of one execution."""

    def __init__(self, model, data, spec: SceneSpec, *, seed: int = 0, rng: np.random.Generator | None = None,
                 plan: Plan | None = None, budget: TimeBudget | None = None,
                 learning: LearningSettings | None = None, video=None):
        self.model, self.data, self.spec = model, data, spec
        self.seed = int(seed)
        self.plan = plan  # the plan being run: its bindings resolve role variables in sub-task params
        self.budget = budget or TimeBudget()
        self.learning = learning or LearningSettings()
        self.video = video  # a VideoRecorder (skills/video.py) fed every control step, or None
        on_step = (lambda drv: video.capture(drv.data)) if video is not None else None
        self.driver = Driver(model, data, rng=rng, on_step=on_step)
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

    def graph(self):
        """The scene graph of the current state, as the robot perceives it."""
        from anomalygen.scene.graph import scene_graph

        return scene_graph(self.model, self.data, self.spec)
