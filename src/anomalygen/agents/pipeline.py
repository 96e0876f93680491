"""Our detect and plan stages as an agent: the calls the pipeline would make, one fix call per hazard.

Why: the skill-level env must judge our own robot exactly as ``anomalygen run`` does, or its figures
would say nothing about the pipeline. So the agent makes the stages' choices through their own code:

1. at ``reset``, the configured detector (``detect/stage.py::detect_scene``: the rules by default) reads
   the scene graph the builder saved, as the detect stage does (``info["built_graph"]``);
2. the plan stage's choice of fixes (``plan/fixes.py::choose_fixes``: known classes, most severe first,
   one per object, roles bound from the perceived graph); a scene the plan stage cannot plan (a fix
   with no skill yet) is left alone, as no plan is made there;
3. one ``fix(object, class, role=...)`` call per fix, with every role the plan stage chose;
4. with ``learn.recheck``, ``wait`` (the learn stage's settle before it looks again), then a fix call
   for each hazard its own actions created (``learn/recheck.py``), then ``done``.

The env plans each fix call with the knowledge base's recipe, seeds its episode as the learn stage
does and runs the sub-tasks through the learn stage's loop, so a run of this agent is a run of the
pipeline; ``docs/benchmarks.md`` measures how often the two agree, run by run, and why they differ.
"""

from __future__ import annotations

from anomalygen.agents.base import Agent
from anomalygen.agents.vocabulary import DONE, FIX, WAIT, Call

LOOK = "look again"  # a step of the queue: wait, then plan the repairs from what is seen


class Pipeline(Agent):
    """The rule detector and the knowledge planner of the pipeline, as calls of the skill vocabulary."""

    observe = ("graph",)  # the scene graph, as the rule detector reads it

    def __init__(self, settings=None):
        from anomalygen.config import Settings

        self.settings = settings if settings is not None else Settings()
        self.queue: list = []
        self.before = None
        self.detection = None
        self.task_id = ""

    def reset(self, obs, info):
        from anomalygen.detect.stage import detect_scene
        from anomalygen.errors import ItemFailed
        from anomalygen.knowledge import load_kb
        from anomalygen.plan.fixes import choose_fixes
        from anomalygen.plan.planner import plan_from_kb
        from anomalygen.schema import SceneGraph

        s = self.settings
        kb = load_kb()
        self.before = SceneGraph.model_validate(obs["graph"])  # the learn stage's "before" for its look again
        built = SceneGraph.model_validate(info["built_graph"]) if info.get("built_graph") else self.before
        self.task_id = built.scene_id  # names the detection and the plan; the bench files them by scene
        self.detection = detect_scene(self.task_id, built, s)
        hyps = [h.model_dump(mode="json") for h in self.detection.hypotheses]
        try:
            fixes, _dropped = choose_fixes(hyps, built, kb, max_fixes=s.plan.max_fixes, min_score=s.plan.min_score)
            for f in fixes:  # the plan stage fails the scene when one of its fixes cannot be planned
                plan_from_kb(self.task_id, f.hazard_class, f.bindings, source="detected", sac_actions=s.plan.sac_actions)
        except ItemFailed:
            fixes = []
        self.queue = [fix_call(f, kb) for f in fixes]
        if fixes and s.learn.recheck:
            self.queue.append(LOOK)
        self.queue.append(DONE)

    def act(self, obs):
        if not self.queue:
            return DONE
        step = self.queue.pop(0)
        if step == LOOK:
            self.queue.insert(0, _Repairs())
            return Call(skill=WAIT)
        if isinstance(step, _Repairs):
            self.queue[:0] = self._repairs(obs)
            return self.act(obs)
        return step

    def _repairs(self, obs) -> list:
        """Fix calls for the hazards the plan's actions created (learn/recheck.py), seen after the wait."""
        from anomalygen.knowledge import load_kb
        from anomalygen.learn.recheck import new_hazards, repair_fixes
        from anomalygen.schema import SceneGraph

        kb = load_kb()
        after = SceneGraph.model_validate(obs["graph"])
        fixes, _problems = repair_fixes(new_hazards(self.before, after, kb), after, kb,
                                        max_fixes=self.settings.plan.max_fixes)
        return [fix_call(f, kb) for f in fixes]

    def detections(self):
        return self.detection


class _Repairs:
    """A place in the queue: the repairs are planned when the agent gets there."""


def fix_call(fix, kb) -> Call:
    """``fix(object, class, role=...)`` with every role of the plan stage's binding."""
    hc = kb.hazard_classes[fix.hazard_class]
    roles = {k.lstrip("$"): v for k, v in fix.bindings.items() if k != hc.hazard_variable}
    return Call(skill=FIX, args={"object": fix.object, "hazard_class": fix.hazard_class, **roles})
