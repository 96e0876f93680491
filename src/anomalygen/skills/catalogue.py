"""The registry with every skill loaded: import ``skill_for`` / ``lookup`` from here.

Skills register themselves when their module is imported (``@register`` in
:mod:`~anomalygen.skills.scripted.actions`, :mod:`~anomalygen.skills.learned.sac_subtask` and
:mod:`~anomalygen.skills.learned.part_subtask`); this module imports them all, so whoever asks the
registry through it sees the whole table. A new skill module is added to the imports below.
"""

from __future__ import annotations

from anomalygen.skills.learned import part_subtask, sac_subtask
from anomalygen.skills.registry import ANY, Skill, SkillOutcome, UnknownSkill, lookup, registered, skill_for
from anomalygen.skills.scripted import actions

SKILL_MODULES = (actions, sac_subtask, part_subtask)

__all__ = ["ANY", "SKILL_MODULES", "Skill", "SkillOutcome", "UnknownSkill", "lookup", "registered", "skill_for"]
