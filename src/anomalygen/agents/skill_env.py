"""The skill-level Gymnasium env of a built scene: one step is one call of the robot's skill vocabulary.

Why: an agent of any kind (our pipeline, an LLM, a random baseline, yours) should be judged on the
same scenes by the same referee, choosing from the same skills. ``anomalygen.make_env(scene_dir,
level="skills")`` gives this env wrapped in the referee's :class:`~anomalygen.referee.env.JudgedEnv`.

- Observation (``agents/observe.py``): a dict of ``image`` (the front camera's RGB; ``cameras``,
  ``width``, ``height``), ``scene_text`` (the paper's textual scene description, what the LLM detector
  reads) and ``objects`` (the same as a structured list); ``observe=`` picks keys, ``graph`` adds the
  scene graph the rule detector reads.
- Action: one call, as text or structured (``agents/vocabulary.py``: ``pick_place(knife_0, drawer_0)``,
  ``switch_off(stove_0, knob_2)``, ``close(fridge_0, door)``, ``fix(...)``, ``wait``, ``done``). The
  action space is ``Text``; a dict or :class:`~anomalygen.agents.vocabulary.Call` is taken too. A call is
  planned into sub-tasks by the planner's machinery (``agents/expand.py``) and run by the learn stage's
  loop (``learn/execute.py::run_subtasks``: retries, SAC with its primitive fallback) in one
  :class:`~anomalygen.skills.episode.Episode`, seeded as the learn stage seeds it.
- An invalid call costs a step and puts the reason in ``info["error"]``; the env never raises on an action.
- The episode ends on ``done`` (terminated) or after ``max_calls`` calls or the episode's control-step
  budget (truncated); the scene settles for ``learn/execute.py::FINAL_SETTLE_STEPS`` control steps
  first, as the learn stage settles before it saves the final state. The reward is 0: the verdict
  is the referee's, added to ``info`` by the wrapper.
- Perception only, as the low-level env: the scene is loaded through ``world.perception``; ``info``
  holds no task words, no task id and nothing of the answer key. At ``reset`` it holds the episode's
  ``seed``, the vocabulary (``skills``), ``max_calls`` and ``built_graph``: the scene graph the builder
  saved with the scene, which the detect stage reads (it differs from the live graph of the same state
  by micrometres). The episode is seeded with the seed and the scene folder's name, as the learn stage
  seeds it with the task id (``rng.item_rng``).
"""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from anomalygen.agents import observe as obs_mod
from anomalygen.agents.vocabulary import DONE, VOCABULARY, WAIT, WAIT_STEPS, CallError, SceneView, parse_call
from anomalygen.errors import AnomalygenError
from anomalygen.knowledge.predicates import PredicateError

ENV_ID = "anomalygen/Skills-v0"
MAX_CALLS = 12  # calls per episode: our pipeline makes at most 3 fixes, a look, 3 repairs and done
MAX_ACTION_CHARS = 2000


class SkillEnv(gym.Env):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 1}

    def __init__(self, scene_dir: str | Path, *, max_calls: int | None = MAX_CALLS,
                 observe=obs_mod.DEFAULT_OBSERVE, cameras=("front",), width: int = 320, height: int = 240,
                 settings=None, render_mode: str | None = "rgb_array"):
        from anomalygen.config import Settings
        from anomalygen.skills.episode import LearningSettings

        self.scene_dir = Path(scene_dir)
        self.task_id = self.scene_dir.name  # the folder's name (the task id): seeds the episode, never shown
        self.max_calls = None if max_calls is None else int(max_calls)
        self.observe_keys = tuple(observe)
        self.cameras = tuple(cameras)
        self.width, self.height, self.render_mode = int(width), int(height), render_mode
        s = settings if settings is not None else Settings()
        self.learning = LearningSettings(sac_steps=s.learn.sac_steps, reward_mode=s.learn.reward_mode,
                                         n_envs=s.learn.n_envs)
        self.retries = s.learn.retries
        self.sac_actions = tuple(s.plan.sac_actions)
        self.observation_space = obs_mod.observation_space(self.observe_keys, self.cameras, self.width, self.height)
        self.action_space = spaces.Text(max_length=MAX_ACTION_CHARS, min_length=0,
                                        charset="".join(sorted(obs_mod.CHARSET)))
        self.episode = self.model = self.data = self.scene = None
        self._renderer = None
        self._kb = None
        self.calls = 0
        from anomalygen.scene_files import SCENE_SPEC

        if not (self.scene_dir / SCENE_SPEC).is_file():
            raise FileNotFoundError(f"no built scene in {self.scene_dir} (no {SCENE_SPEC})")

    # ------------------------------------------------------------------ gym API
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        episode_seed = int(seed) if seed is not None else int(self.np_random.integers(2**31 - 1))
        self._load(episode_seed)
        self.calls = 0
        info = {"seed": episode_seed, "skills": [c.signature() for c in VOCABULARY.values()],
                "max_calls": self.max_calls, "built_graph": self._built_graph()}
        return self._observe(), info

    def step(self, action):
        from anomalygen.learn.execute import FINAL_SETTLE_STEPS

        ep = self.episode
        self.calls += 1
        s0 = ep.steps
        info: dict = {"call": None, "error": None, "executed": []}
        terminated = False
        try:
            call = self._valid(action)
            info["call"] = call.text()
            if call.skill == DONE:
                ep.settle(FINAL_SETTLE_STEPS)
                terminated = True
            elif call.skill == WAIT:
                ep.settle(int(call.args.get("steps", WAIT_STEPS)))
            else:
                info["executed"] = [r.model_dump(mode="json") for r in self._run(call)]
        except CallError as exc:
            info["error"] = str(exc)
        except (AnomalygenError, PredicateError) as exc:  # a skill's expected failure: this call, not the episode
            info["error"] = f"{info['call']}: {exc}"
        truncated = not terminated and bool(
            (self.max_calls is not None and self.calls >= self.max_calls) or ep.budget.spent(ep.steps))
        if truncated:
            ep.settle(FINAL_SETTLE_STEPS)
        info["control_steps"] = ep.steps - s0
        info["calls_left"] = None if self.max_calls is None else max(0, self.max_calls - self.calls)
        return self._observe(), 0.0, terminated, truncated, info

    def render(self):
        if self.render_mode != "rgb_array":
            return None
        return self._images()[self.cameras[0]]

    def close(self):
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    # ------------------------------------------------------------------ helpers
    def _load(self, seed: int = 0) -> None:
        """A fresh load of the scene and a fresh Episode, as the learn stage makes one per execution
        (skills change the model as they go: a fresh load is the scene as built)."""
        from anomalygen.rng import item_rng
        from anomalygen.skills.episode import Episode, EpisodeBudget
        from anomalygen.world.perception import load_perceived_scene

        self.close()
        self.model, self.data, self.scene = load_perceived_scene(self.scene_dir)
        self.episode = Episode(self.model, self.data, self.scene, seed=seed, rng=item_rng(seed, self.task_id),
                               budget=EpisodeBudget(), learning=self.learning)

    @property
    def kb(self):
        if self._kb is None:
            from anomalygen.knowledge import load_kb

            self._kb = load_kb()
        return self._kb

    def graph(self):
        """The scene graph of the current state, as the robot perceives it."""
        return self.episode.graph()

    def _built_graph(self) -> dict | None:
        """The scene graph the builder saved with the scene: what the detect stage reads."""
        from anomalygen.world.perception import load_scene_graph

        g = load_scene_graph(self.scene_dir)
        return g.model_dump(mode="json") if g is not None else None

    def _valid(self, action):
        from anomalygen.agents.vocabulary import validate_call

        if isinstance(action, str) and len(action) > MAX_ACTION_CHARS:
            raise CallError(f"an action of {len(action)} characters is no call (at most {MAX_ACTION_CHARS})")
        call = parse_call(action)
        view = SceneView.from_objects(obs_mod.objects_of(self.graph(), self.scene))
        return validate_call(call, view, self.kb)

    def _run(self, call):
        """Plan the call on the scene as it stands and run its sub-tasks in the episode."""
        from anomalygen.agents.expand import plan_for_call
        from anomalygen.learn.execute import run_subtasks
        from anomalygen.learn.recheck import spec_as_it_stands

        ep = self.episode
        graph = ep.graph()
        plan = plan_for_call(call, graph, spec_as_it_stands(ep.spec, graph), self.kb, self.task_id,
                             sac_actions=self.sac_actions)
        if why := ep.budget.spent(ep.steps):
            raise CallError(f"not executed: {why}")
        return run_subtasks(ep, plan, self.retries)

    def _images(self) -> dict[str, np.ndarray]:
        if self._renderer is None:
            from anomalygen.world.render import SceneRenderer

            self._renderer = SceneRenderer(self.model, self.width, self.height)
        return {cam: self._renderer.render(self.data, cam) for cam in self.cameras}

    def _observe(self) -> dict:
        images = self._images() if "image" in self.observe_keys else {}
        return obs_mod.observe(self.graph(), self.scene, self.observe_keys, images)


def register() -> None:
    """Register ``anomalygen/Skills-v0`` with Gymnasium (idempotent): ``gym.make(ENV_ID, scene_dir=...)``.
    The registry's time limit is the env's own ``max_calls``; the env ends its episodes itself (it settles
    the scene first), so the wrapper never has to."""
    if ENV_ID not in gym.registry:
        gym.register(id=ENV_ID, entry_point="anomalygen.agents.skill_env:SkillEnv", max_episode_steps=MAX_CALLS)


register()
