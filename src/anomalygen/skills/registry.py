"""The skill registry: every skill registers itself under (method, action); the learn stage asks it.

A skill is a class with ``run(episode, subtask) -> SkillOutcome`` (:class:`Skill`), registered with
``@register(method, action, ...)``: the method is the plan schema's ``SkillMethod`` value
("primitive", "sac"), the action the sub-task's primitive (``"pick"``, ``"push"``) or a family of
sub-tasks (``"switch_off"``). Two refinements keep the table small and honest:

* ``ANY``: a skill registered under ``(method, ANY)`` runs every action of its method that has no
  skill of its own (SAC learns whatever the sub-task's reward asks, so one learned skill covers them);
* ``Skill.claims(episode, subtask)``: a family skill recognises its sub-tasks in the scene (a knob
  driven to off is the switch-off family even when the planner did not say so) and is chosen first.

:func:`lookup` raises :class:`UnknownSkill`, which names the registered actions, when nothing fits.
Skills register when their module is imported; :mod:`anomalygen.skills.catalogue` imports them all.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

from anomalygen.errors import AnomalygenError

if TYPE_CHECKING:  # pragma: no cover
    from anomalygen.schema import SubTask

ANY = "*"  # the action of a skill that runs every action of its method without a skill of its own


@dataclass
class SkillOutcome:
    """What one run of a skill did: success as the skill saw it, control steps spent, and why."""

    success: bool
    steps: int
    detail: str = ""


class Skill:
    """A registered skill; subclasses set nothing by hand: ``register`` fills ``method`` and ``action``."""

    method: ClassVar[str] = ""
    action: ClassVar[str] = ""

    def run(self, episode, subtask: SubTask) -> SkillOutcome:  # pragma: no cover - the contract
        raise NotImplementedError

    @classmethod
    def claims(cls, episode, subtask: SubTask) -> bool:
        """Does this (family) skill recognise ``subtask`` in the episode's scene? Plain skills do not."""
        return False

    @classmethod
    def key(cls) -> str:
        """``method:action``, as results record which skill executed a sub-task."""
        return f"{cls.method}:{cls.action}"


class UnknownSkill(AnomalygenError, LookupError):
    """No skill is registered for a (method, action)."""


_SKILLS: dict[tuple[str, str], type[Skill]] = {}


def register(method: str, *actions: str):
    """Class decorator: register the skill under ``(method, action)`` for each action given.

    A class registered under several actions is copied per action (a subclass), so each entry knows
    the action it stands for. Registering a key twice is an error: one action, one skill."""

    def deco(cls: type[Skill]) -> type[Skill]:
        for action in actions:
            key = (str(method), str(action))
            if key in _SKILLS:
                raise ValueError(f"skill {key[0]}:{key[1]} is registered twice ({_SKILLS[key].__name__}, {cls.__name__})")
            entry = cls if len(actions) == 1 else type(cls.__name__, (cls,), {"__module__": cls.__module__})
            entry.method, entry.action = key
            _SKILLS[key] = entry
        return cls

    return deco


def registered(method: str | None = None) -> list[tuple[str, str]]:
    """The registered (method, action) keys, sorted; only those of ``method`` when given."""
    return sorted(k for k in _SKILLS if method is None or k[0] == method)


def lookup(method: str, action: str) -> type[Skill]:
    """The skill for ``(method, action)``: its own, else the method's ``ANY`` skill."""
    found = _SKILLS.get((method, action)) or _SKILLS.get((method, ANY))
    if found is None:
        names = ", ".join(a for m, a in registered(method)) or "none"
        raise UnknownSkill(f"no {method} skill for action {action!r}; registered {method} actions: {names}")
    return found


def skill_for(episode, subtask: SubTask) -> type[Skill]:
    """The skill that runs ``subtask``: a family skill of its method that claims it, else
    ``lookup(method, primitive)``."""
    method = str(subtask.method)  # a SkillMethod (a StrEnum) or its value
    for (m, _), cls in sorted(_SKILLS.items()):
        if m == method and cls.claims(episode, subtask):
            return cls
    return lookup(method, subtask.primitive or "")
