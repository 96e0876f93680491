"""The episode's budget counts control steps, so when it runs out does not depend on the machine."""

from __future__ import annotations

from anomalygen.schema import Plan, SceneSpec, SubTask, SuccessSpec
from anomalygen.skills.episode import EpisodeBudget
from support.testbed import scene_with_obstacle


def test_budget_is_control_steps_and_the_wall_clock_is_only_a_safety_net():
    budget = EpisodeBudget(max_steps=100)
    assert budget.spent(99) == ""
    assert budget.spent(100) == "the episode's 100 control steps are spent"
    assert EpisodeBudget(seconds=0.0).spent(0) == "the episode's 0 s wall-clock safety net is spent"


def test_sub_tasks_after_the_step_budget_are_not_executed():
    from anomalygen.learn.execute import run_subtasks
    from anomalygen.skills.episode import Episode

    m, d = scene_with_obstacle()
    spec = SceneSpec(scene_id="tb", task_id="t", room="kitchen", seed=0, objects=[])
    ep = Episode(m, d, spec, budget=EpisodeBudget(max_steps=1))
    steps = [SubTask(id=f"s{i}_grasp", description="pick it up", method="primitive", primitive="grasp",
                     params={"object": obj}) for i, obj in enumerate(("box_0", "toy_0"))]
    plan = Plan(task_id="t", source="detected", engine="knowledge", subtasks=steps, success=SuccessSpec())
    first, second = run_subtasks(ep, plan, retries=1)
    assert first.steps > 1  # started within the budget, it ran to its end
    assert second.steps == 0 and not second.success
    assert second.detail == "not executed: the episode's 1 control steps are spent"
