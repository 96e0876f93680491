"""The switch-off family: a built appliance scene, the relative observation, the env contract, the
scripted reference and (slow) the shipped warm start switching a built scene's appliance off."""

from __future__ import annotations

import numpy as np
import pytest

from support.kb_scenes import build_with_kb_plans


def make_task(task_id, appliance, placement="counter"):
    from anomalygen.schema import TaskProposal

    return TaskProposal(
        id=task_id, name=f"task {task_id}", explanation="test", description=f"The {appliance} is left on.",
        category="household_hazard", hazard_class="switch_off_appliance", target_asset=appliance,
        scenario=dict(hazard_object=appliance, room="kitchen", placement=placement, co_objects=[]),
        articulations=[dict(object=appliance, part="knob", initial_state="on")],
        provenance=dict(engine="knowledge", mode="brainstorm"))


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    return build_with_kb_plans({"toaster": make_task("t-toaster", "Toaster"),
                                "microwave": make_task("t-microwave", "Microwave")},
                               tmp_path_factory.mktemp("switch_scenes"), clutter=0)


def _held_start(scene_dir, plan, k: int = 0):
    from anomalygen.skills.episode import Episode
    from anomalygen.skills.learned.part_env import PartStart
    from anomalygen.skills.learned.part_subtask import far_value
    from anomalygen.skills.learned.sac_subtask import snapshot
    from anomalygen.skills.part_motion import grasp_part
    from anomalygen.world.graph import load_scene
    from anomalygen.world.perception import perceived_spec

    model, data, spec = load_scene(scene_dir)
    spec = perceived_spec(spec)
    ep = Episode(model, data, spec, rng=np.random.default_rng(0))
    st = plan.subtasks[k]
    joint = str(st.params["joint"])
    js = next(j for o in spec.objects for j in o.joint_states if j.name == joint)
    ok, why = grasp_part(ep, joint)
    assert ok, why
    return ep, PartStart(model, snapshot(model, data), spec, st, dict(plan.bindings), joint,
                          js.closed_value, far_value(js))


def test_planner_hands_the_knob_to_sac(built):
    from anomalygen.schema import SkillMethod

    for _, _spec, plan in built.values():
        assert plan.subtasks and all(st.method == SkillMethod.SAC for st in plan.subtasks)
        assert all(st.params["family"] == "switch_off" for st in plan.subtasks)


def test_part_env_contract_and_the_reference_turns_a_held_knob_off(built):
    from gymnasium.utils.env_checker import check_env

    from anomalygen.skills.learned.part_env import HORIZON, PartTurnEnv, make_part_env
    from anomalygen.skills.part_motion import OBS_DIM, reference_action

    scene_dir, spec, plan = built["toaster"]
    _, start = _held_start(scene_dir, plan)
    check_env(PartTurnEnv([start]), skip_render_check=True)
    env = make_part_env([start])
    assert env.spec.max_episode_steps == HORIZON == env.unwrapped.horizon == 60  # the registration's TimeLimit
    obs, _ = env.reset(seed=3)
    assert obs.shape == (OBS_DIM,)
    assert obs[11] == 1.0 and obs[9] > 0.6  # held, and the knob is well on
    assert np.linalg.norm(obs[0:3]) < 0.2  # the held point is under the cup (dm)
    assert abs(np.linalg.norm(obs[3:6]) - 1.0) < 1e-6  # a unit towards-off direction
    done, info, t = False, {}, 0
    while not done:
        obs, r, term, trunc, info = env.step(reference_action(obs))
        done, t = term or trunc, t + 1
    assert info["is_success"] and t < 40
    q = float(env.unwrapped._cur.data.joint(start.joint).qpos[0])
    assert abs(q - start.closed) <= 0.05 * abs(start.far - start.closed)  # physically at off
    env.close()


def test_observation_is_relative_the_same_part_state_reads_alike_in_two_scenes(built):
    """Two appliances of different types, sizes and places: the held-knob observations share their
    layout and magnitudes (no world coordinates), which is what lets one policy serve both."""
    from anomalygen.skills.learned.part_env import PartTurnEnv

    obs = []
    for key in ("toaster", "microwave"):
        scene_dir, _, plan = built[key]
        _, start = _held_start(scene_dir, plan)
        env = PartTurnEnv([start], start_noise=0.0)
        obs.append(env.reset(seed=0)[0])
        env.close()
    a, b = obs
    assert np.all(np.abs(a[:9]) < 1.0) and np.all(np.abs(b[:9]) < 1.0)
    assert a[10] == b[10] == 1.0 and a[16] == b[16] == 1.0


@pytest.mark.slow
def test_vectorised_sac_fine_tunes_from_a_warm_start(built, tmp_path):
    """train_sac with 2 DummyVecEnv envs loads a saved policy, keeps its weights, trains and evaluates."""
    from anomalygen.skills.learned.part_env import make_part_env
    from anomalygen.skills.learned.sac import train_sac

    scene_dir, _, plan = built["toaster"]
    _, start = _held_start(scene_dir, plan)
    model, res = train_sac(lambda: make_part_env([start]), 0, net_arch=(32, 32), eval_episodes=1)
    path = tmp_path / "p.zip"
    model.save(str(path))
    tuned, res = train_sac(lambda: make_part_env([start]), 200, eval_every=100, eval_episodes=2, learning_starts=50,
                           n_envs=2, init_model=str(path))
    assert tuned.n_envs == 2 and [c["step"] for c in res.curve] == [0, 100, 200]
    assert res.steps == 200


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason=(
    "the shipped warm start turns the toaster's knob only by dragging and tipping the toaster (0.75 rad, "
    "8.7 cm before the drag/tip stop); the stop now halts it and the scripted skill switches it off. "
    "It needs retraining with a penalty for moving the appliance (benchmarks/train_warm_start.py)"))
def test_shipped_warm_start_switches_a_built_toaster_off(built):
    """The learn stage's path: the planner's SAC sub-task, the shipped policy (no fine-tuning budget),
    executed on the Driver; the physical outcome is the knob joint at off."""
    from anomalygen.learn.execute import execute_plan
    from anomalygen.schema import SkillMethod
    from anomalygen.skills.learned.part_subtask import warm_start_path

    assert warm_start_path() is not None and warm_start_path().stat().st_size < 2_000_000
    scene_dir, spec, plan = built["toaster"]
    res = execute_plan(scene_dir, plan, seed=0, sac_steps=0)
    st = res.subtasks[0]
    assert st.method == SkillMethod.SAC and "warm start" in st.detail and "fell back" not in st.detail, st.detail
    assert st.executed_by == "sac:switch_off"  # the family skill, not the primitive behind it
    assert res.success and all(p.holds for p in res.final_predicates), st.detail
