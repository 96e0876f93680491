"""Two reference agents: one that leaves every scene as it is, one that acts at random.

Why: a score means something only beside what doing nothing and acting blindly score. ``DoNothing``
must resolve no hazard and leave every hazard-free scene alone; ``Random`` measures what a valid but
aimless call does (the referee counts the new hazards and the safe objects it moved).
"""

from __future__ import annotations

from anomalygen.agents.base import Agent
from anomalygen.agents.vocabulary import (
    DONE,
    FIX,
    VOCABULARY,
    WAIT,
    Call,
    CallError,
    SceneView,
    validate_call,
)

#: What Random draws from: every skill that moves something (not fix, which runs a hazard's whole
#: recipe, nor wait or done).
RANDOM_SKILLS = tuple(name for name in VOCABULARY if name not in (FIX, WAIT, DONE))
DRAWS = 20  # tries at a valid call for a skill before another skill is drawn


class DoNothing(Agent):
    """Ends every episode at once: the scene is judged as built."""

    observe = ()

    def act(self, obs):
        return DONE


class Random(Agent):
    """``calls`` valid calls drawn at random, then ``done``.

    Each call: a skill drawn uniformly from :data:`RANDOM_SKILLS`, then each required argument
    uniformly from the objects it may name (a movable object for what is carried, any other object
    for a destination, one of the object's parts of the right kind); a draw the env would refuse is
    drawn again. Seeded per episode from the env's seed and the scene graph's id."""

    observe = ("objects",)

    def __init__(self, calls: int = 2):
        self.calls = int(calls)
        self.made = 0
        self.rng = None

    def reset(self, obs, info):
        from anomalygen.rng import item_rng

        scene = (info.get("built_graph") or {}).get("scene_id", "")
        self.rng = item_rng(int(info.get("seed", 0)), "random-agent", str(scene))
        self.made = 0

    def act(self, obs):
        from anomalygen.knowledge import load_kb

        if self.made >= self.calls:
            return DONE
        self.made += 1
        view = SceneView.from_objects(obs["objects"])
        kb = load_kb()
        skills = list(RANDOM_SKILLS)
        while skills:
            skill = skills.pop(int(self.rng.integers(len(skills))))
            for _ in range(DRAWS):
                call = self._draw(skill, view)
                if call is None:
                    break
                try:
                    return validate_call(call, view, kb)
                except CallError:
                    continue
        return DONE  # nothing in the scene can be acted on

    def _draw(self, skill: str, view: SceneView) -> Call | None:
        from anomalygen.schema import part_labels

        objs = sorted(view.objects.values(), key=lambda o: o.name)
        args: dict[str, str] = {}
        for p in VOCABULARY[skill].params:
            if not p.required:
                continue
            if p.kind == "movable":
                pool = [o.name for o in objs if o.movable]
            elif p.kind == "object":
                pool = [o.name for o in objs if o.name not in args.values()]
                if skill in ("open", "close"):
                    pool = [o.name for o in objs if any(part_labels.is_closure(q.label) for q in o.parts)]
                elif skill == "switch_off":
                    pool = [o.name for o in objs if any(part_labels.is_switch(q.label) for q in o.parts)]
            else:
                return None
            if not pool:
                return None
            args[p.name] = pool[int(self.rng.integers(len(pool)))]
        return Call(skill=skill, args=args)
