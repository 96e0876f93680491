"""The referee: the answer key and the judgement, on the far side from the robot.

The builder writes each scene's hidden ``truth.json`` through :mod:`anomalygen.truth.manifest`; after
the robot's items have finished, the judge stage (:mod:`anomalygen.referee.stage`, ``anomalygen
judge``) scores the detections and judges every run's settled final state. Nothing on the robot's
side (detect, plan, learn, robot, skills) imports this package; ``tests/test_layout.py``
enforces it.

Public entry points:

- :func:`judge` — the verdict on a simulator state of a built scene (a run's final state, or an
  outside policy's episode): releases what the robot holds, lets the scene settle on a copy, and
  judges every hazard of the truth;
- :func:`load_verdict` — a learn run's verdict from a run folder;
- :func:`load_manifest` — a scene's truth manifest;
- :class:`~anomalygen.referee.env.JudgedEnv` — a Gymnasium wrapper that puts the verdict in ``info``
  at the end of an episode, or judges only when asked (what ``anomalygen.make_env`` returns, with
  ``judge="end"`` or ``"never"``; ``anomalygen.make_vec_env`` gives a Stable-Baselines3 VecEnv of them).
"""

from __future__ import annotations

from anomalygen.referee.settle import judge
from anomalygen.referee.stage import load_verdict
from anomalygen.truth.manifest import load_manifest

__all__ = ["judge", "load_manifest", "load_verdict"]
