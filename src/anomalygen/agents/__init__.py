"""Agents and the skill-level env they act in: any agent, judged by the referee.

``anomalygen.make_env(scene_dir, level="skills")`` is :class:`~anomalygen.agents.skill_env.SkillEnv`
(one step: one call of the skill vocabulary, ``agents/vocabulary.py``) in the referee's wrapper. The
baselines: :class:`Pipeline` (our detect and plan stages as an agent), :class:`DoNothing`,
:class:`Random` (valid calls, uniformly) and :class:`LLMAgent` (the configured LLM, with the paper's
detection prompt and the skill vocabulary). ``anomalygen bench`` runs any of them, or yours, over a
suite (``docs/agents.md``).

The robot's side: nothing here reads the answer key, the builder or the referee
(``tests/test_layout.py``). Names load lazily, so ``anomalygen.agents:Pipeline`` costs no simulator
import until an agent is made.
"""

from __future__ import annotations

import importlib

_NAMES = {
    "Agent": "anomalygen.agents.base",
    "load_agent": "anomalygen.agents.base",
    "Pipeline": "anomalygen.agents.pipeline",
    "DoNothing": "anomalygen.agents.baselines",
    "Random": "anomalygen.agents.baselines",
    "LLMAgent": "anomalygen.agents.llm_agent",
    "SkillEnv": "anomalygen.agents.skill_env",
    "Call": "anomalygen.agents.vocabulary",
    "VOCABULARY": "anomalygen.agents.vocabulary",
}

__all__ = sorted(_NAMES)


def __getattr__(name: str):
    if name in _NAMES:
        return getattr(importlib.import_module(_NAMES[name]), name)
    raise AttributeError(f"module 'anomalygen.agents' has no attribute {name!r}")
