"""CEM with the simulator as the model: the Gymnasium Ant walks to a goal it was not scripted for."""

import numpy as np

from support.cem import CEMConfig, WalkToGoal, run_cem


def test_ant_walks_to_goal_by_cem():
    task = WalkToGoal(goal=(2.0, 1.0), radius=0.5)
    res = run_cem(task, CEMConfig(horizon=150, frameskip=4), np.random.default_rng(0))
    start = np.linalg.norm(np.asarray(task.goal))
    assert res.success, f"final distance {res.final_distance:.2f}"
    assert res.final_distance <= 0.5 < start
    assert res.steps < 150
    # it must not have fallen on the way: torso stays above the unhealthy height
    assert min(q[2] for q in res.qpos_trace) > 0.3


def test_cost_penalises_a_fallen_ant():
    task = WalkToGoal(goal=(1.0, 0.0))
    upright = np.zeros(15)
    upright[2], upright[3] = 0.6, 1.0
    fallen = upright.copy()
    fallen[2] = 0.1
    assert task.cost(fallen[None])[0] > task.cost(upright[None])[0] + 2.9
