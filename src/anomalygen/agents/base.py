"""What an agent is: a small class the bench drives through the skill-level env.

An agent has two methods and two optional attributes::

    class MyAgent(Agent):
        observe = ("scene_text", "objects")      # the observation keys it reads (default: image, scene_text, objects)

        def reset(self, obs, info):              # a new episode: info["skills"] lists the vocabulary
            self.todo = ["switch_off(stove_0)", "done"]

        def act(self, obs):                      # one call: text, a dict, or a Call
            return self.todo.pop(0) if self.todo else "done"

        def result(self, info):                  # optional: the env's info after each call (its error,
            pass                                 # the sub-tasks it ran)

        def detections(self):                    # optional: what it believes is wrong (schema.Hypothesis),
            return None                          # scored against the scene's truth when the episode is over

The bench makes one with no arguments, or with ``settings=`` (the run's ``Settings``) when its
constructor takes them, once per worker, and calls ``reset`` at every episode.
"""

from __future__ import annotations

import importlib
import inspect

from anomalygen.agents.observe import DEFAULT_OBSERVE
from anomalygen.errors import UserError


class Agent:
    """The base of the shipped agents; any class with ``reset`` and ``act`` will do."""

    observe: tuple[str, ...] = DEFAULT_OBSERVE

    def reset(self, obs: dict, info: dict) -> None:
        pass

    def act(self, obs: dict):  # pragma: no cover - the contract
        raise NotImplementedError

    def result(self, info: dict) -> None:
        """The env's ``info`` after the agent's last call (``error``, ``executed``): optional feedback."""

    def detections(self):
        """The hazards the agent reports for the episode (``schema.Hypothesis``), or None."""
        return None


def load_agent(spec: str) -> type:
    """``module:Class`` (``anomalygen.agents:Pipeline``) -> the class; UserError naming what is wrong."""
    module, _, name = spec.partition(":")
    if not module or not name:
        raise UserError(f"an agent is named MODULE:CLASS (e.g. anomalygen.agents:Pipeline), not {spec!r}")
    try:
        cls = getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError) as exc:
        raise UserError(f"cannot load the agent {spec}: {exc}") from exc
    if not (callable(getattr(cls, "reset", None)) and callable(getattr(cls, "act", None))):
        raise UserError(f"{spec} is no agent: it needs reset(obs, info) and act(obs)")
    return cls


def make_agent(cls: type, settings=None, **options):
    """An instance of the agent class, given ``settings`` when its constructor takes them."""
    try:
        params = inspect.signature(cls).parameters
    except (TypeError, ValueError):
        params = {}
    if settings is not None and "settings" in params:
        options = {"settings": settings, **options}
    return cls(**options)
