"""SAC sub-tasks on a scene: the SubTaskEnv contract and run_sac_subtask in an Episode (test scene door)."""

from __future__ import annotations

import numpy as np
import pytest

from anomalygen.schema import (
    AssetRef,
    JointState,
    PlacedObject,
    Plan,
    PredicateCall,
    RewardSpec,
    RewardTerm,
    SceneSpec,
    SubTask,
    SuccessSpec,
)

HINGE = "cabinet_0:door_hinge"


def door_spec(q: float) -> SceneSpec:
    """A minimal SceneSpec for the test scene's cabinet (what scene_graph needs)."""
    door = JointState(name=HINGE, label="door", value=q, range=(0.0, 1.6), closed_value=0.0)
    cab = PlacedObject(name="cabinet_0", asset=AssetRef(asset_id="cabinet_0", category="Cabinet"), role="target",
                       size=0.4, pos=[0.85, -0.05, 0.0], joint_states=[door], fixed=True)
    return SceneSpec(scene_id="testbed", task_id="t-door", room="kitchen", seed=0, objects=[cab])


def door_plan() -> tuple[SubTask, Plan]:
    reward = RewardSpec(terms=[RewardTerm(kind="joint", joint=HINGE, target=0.0, weight=2.0),
                               RewardTerm(kind="distance", a="ee", b="$target", weight=0.5),
                               RewardTerm(kind="distance", a="ee", b="cabinet_0:door_handle", weight=1.0),
                               RewardTerm(kind="action_penalty", weight=0.01)])
    closed = SuccessSpec(predicates=[PredicateCall(name="joint_closed", args={"object": "$target", "label": "door"})])
    st = SubTask(id="s1_close_joint", description="close the cabinet door", method="sac",
                 params={"object": "cabinet_0"}, reward=reward, success=closed)
    return st, Plan(task_id="t-door", source="ground_truth", engine="knowledge", subtasks=[st], success=closed,
                    bindings={"$target": "cabinet_0"})


def door_episode(q: float = 1.0, *, approach: bool = True):
    """The test scene (no table: the open door would swing into it) with the cup brought to the door."""
    from anomalygen.skills.episode import Episode
    from anomalygen.skills.learned.sac_subtask import pre_position
    from anomalygen.skills.learned.subtask_env import SubTaskReadout
    from support.testbed import build

    tb = build(with_objects=False, door_open=q)
    ep = Episode(tb.model, tb.data, door_spec(q), rng=np.random.default_rng(0))
    st, plan = door_plan()
    if approach:
        note = pre_position(ep, st, plan, SubTaskReadout(ep.model, ep.spec, st, plan.bindings))
        assert note.startswith("cup placed")
    return ep, st, plan


def _push_action(env_or_drv, data) -> np.ndarray:
    """A scripted closing push at the handle (3 cm/step towards 6 cm past it)."""
    from anomalygen.skills import geometry as G

    m = env_or_drv.model
    h = data.site_xpos[m.site("cabinet_0:door_handle").id]
    v = -G.joint_motion_direction(m, data, HINGE, h)
    a = np.zeros(7)
    a[:3] = np.clip((h + 0.06 * v - data.site_xpos[m.site("suction_site").id]) / 0.03, -1, 1)
    return a


@pytest.fixture(scope="module")
def at_door():
    return door_episode()


def test_env_api_and_exact_reset(at_door):
    import mujoco
    from gymnasium.utils.env_checker import check_env

    from anomalygen.skills.learned.sac_subtask import snapshot
    from anomalygen.skills.learned.subtask_env import SubTaskEnv

    ep, st, plan = at_door
    drv = ep.driver
    snap = snapshot(drv.model, drv.data)
    caller_qpos, caller_eq = drv.data.qpos.copy(), drv.model.eq_data.copy()
    env = SubTaskEnv(drv.model, snap, ep.spec, st, plan.bindings)
    check_env(env, skip_render_check=True)
    assert env.action_space.shape == (7,)
    # 7 cup pose + 2 points (cabinet, handle) x 3 + 1 joint + suction + time
    assert env.observation_space.shape == (7 + 6 + 1 + 2,)
    for _ in range(30):
        env.step(env.action_space.sample())
    exact = SubTaskEnv(drv.model, snap, ep.spec, st, plan.bindings, start_noise=0.0)
    for e in (env, exact):
        obs, _ = e.reset(seed=3)
        assert obs.shape == e.observation_space.shape and obs[-1] == 0.0
        assert obs[13] == pytest.approx(float(drv.data.joint(HINGE).qpos[0]))  # the door angle
        got = snapshot(e.model, e.data)
        diff = np.flatnonzero(got != snap)
        if e is exact:
            assert diff.size == 0  # bit-exact restore
        else:  # only the cup target moved, by at most 2 cm per axis
            mocap = e.readout.agent.mocap
            assert 0 < np.abs(e.data.mocap_pos[mocap] - drv.data.mocap_pos[mocap]).max() <= 0.02
            e.data.mocap_pos[mocap] = drv.data.mocap_pos[mocap]
            again = np.empty_like(snap)
            mujoco.mj_getState(e.model, e.data, again, mujoco.mjtState.mjSTATE_INTEGRATION)
            assert np.array_equal(again, snap)
    # the caller's model and data were never touched
    assert np.array_equal(drv.data.qpos, caller_qpos) and np.array_equal(drv.model.eq_data, caller_eq)


def test_reward_is_the_spec_on_the_state_and_success_ends_the_episode(at_door):
    from anomalygen.skills.learned.reward import evaluate_spec
    from anomalygen.skills.learned.sac_subtask import snapshot
    from anomalygen.skills.learned.subtask_env import HORIZON, make_subtask_env

    ep, st, plan = at_door
    drv = ep.driver
    env = make_subtask_env(drv.model, snapshot(drv.model, drv.data), ep.spec, st, plan.bindings)
    u = env.unwrapped
    assert env.spec.max_episode_steps == HORIZON == u.horizon == 100  # the TimeLimit of the registration
    env.reset(seed=0)
    rewards, info, term, t = [], {}, False, 0
    while t < 100:
        t += 1
        _, r, term, trunc, info = env.step(_push_action(u, u.data))
        s = u.state()
        assert r == evaluate_spec(st.reward, s)
        assert set(s["objects"]["cabinet_0"]) == {"pos", "quat", "size"} and s["joints"][HINGE] == u.data.joint(HINGE).qpos[0]
        assert s["objects"]["$target"] is s["objects"]["cabinet_0"]  # role variables resolve
        rewards.append(r)
        if term or trunc:
            break
    assert term and info["is_success"] and info["success"]
    assert u.data.joint(HINGE).qpos[0] < 0.05 * 1.6  # joint_closed's default: 5 % of the range
    assert t % 4 == 0 and rewards[-1] > rewards[0] + 1.0  # predicates checked every 4th step
    # doing nothing leaves it open until the horizon
    env.reset(seed=0)
    for _ in range(100):
        _, _, term, trunc, info = env.step(np.zeros(7))
    assert trunc and not term and not info["is_success"]


def test_env_and_driver_rollout_share_one_control_step(at_door):
    """The same actions from the same snapshot give bit-identical physics on the env and on the Driver."""
    from anomalygen.skills.learned.sac_subtask import restore, snapshot
    from anomalygen.skills.learned.subtask_env import SubTaskEnv, SubTaskReadout, control_step

    ep, st, plan = at_door
    drv = ep.driver
    snap = snapshot(drv.model, drv.data)
    env = SubTaskEnv(drv.model, snap, ep.spec, st, plan.bindings, start_noise=0.0)
    env.reset(seed=0)
    actions = [_push_action(env, env.data) + 0.3 * np.sin(k) for k in range(20)]
    for a in actions:
        env.step(a)
    readout = SubTaskReadout(drv.model, ep.spec, st, plan.bindings)
    frames = []
    drv.on_step = lambda d: frames.append(d.steps)
    drv.frameskip, fs = 2, drv.frameskip
    for t, a in enumerate(actions, 1):
        control_step(readout, drv.model, drv.data, a, t, drv.step)
    drv.frameskip, drv.on_step = fs, None
    assert np.array_equal(drv.data.qpos, env.data.qpos) and len(frames) == 20
    restore(drv.model, drv.data, snap)


def test_suction_action_grabs_and_releases():
    from anomalygen.robot.agent import Agent
    from anomalygen.skills.episode import Episode
    from anomalygen.skills.scripted import primitives as P
    from support.testbed import build

    tb = build(with_cabinet=False)
    ep = Episode(tb.model, tb.data, SceneSpec(scene_id="tb", task_id="t", room="kitchen", seed=0, objects=[]))
    drv = ep.driver
    assert P.grasp(ep, "box_0").success
    drv.agent.release(drv.data)
    bot = Agent(drv.model)
    far = np.zeros(7)
    bot.apply_action(drv.data, np.r_[far[:6], 1.0])
    assert drv.held == "box_0"
    assert drv.model.eq_data[drv.model.equality("suction__box_0").id, 10] == 1.0  # free object: held rigidly
    bot.apply_action(drv.data, np.r_[far[:6], -0.2])
    assert drv.held is None


def test_zero_budget_is_not_executed(at_door):
    from anomalygen.skills.learned.sac_subtask import run_sac_subtask

    ep, st, plan = at_door
    s0 = ep.steps
    res = run_sac_subtask(ep, st, plan, steps=0, seed=0)
    assert (res.success, res.steps, res.detail) == (False, 0, "not executed: sac_steps is 0") and ep.steps == s0


@pytest.mark.slow
def test_run_sac_subtask_trains_and_replays_on_the_driver_deterministically():
    from anomalygen.skills.learned.sac_subtask import run_sac_subtask

    outs = []
    for _ in range(2):
        ep, st, plan = door_episode(approach=False)
        drv = ep.driver
        frames: list[int] = []
        drv.on_step = frames.append
        q0 = float(drv.data.joint(HINGE).qpos[0])
        res = run_sac_subtask(ep, st, plan, steps=400, seed=0, eval_episodes=2, learning_starts=100)
        q1 = float(drv.data.joint(HINGE).qpos[0])
        assert res.steps == drv.steps == len(frames) > 0 and frames[0] is drv  # pre-positioning + rollout, all seen by the hook
        assert "SAC 400 steps: best eval success" in res.detail and "cup placed" in res.detail
        assert f"door_hinge = {q1:.3f}" in res.detail and q1 != q0
        rollout = int(res.detail.split(" in ")[1].split(" steps")[0])
        assert rollout == 100 or res.success
        outs.append((res.success, res.steps, res.detail, drv.data.qpos.copy()))
    assert outs[0][:3] == outs[1][:3] and np.array_equal(outs[0][3], outs[1][3])


@pytest.mark.slow
def test_a_closing_reward_about_an_already_closed_part_moves_to_the_open_one(tmp_path):
    """The planner names a fridge's first joint (the freezer); the open one is the door."""
    from anomalygen.config import Settings
    from anomalygen.plan.planner import plan_from_kb
    from anomalygen.scene.build import build_scene
    from anomalygen.skills.episode import Episode
    from anomalygen.skills.learned.sac_subtask import retarget_joints
    from anomalygen.world.graph import load_scene
    from support.kb_scenes import kb_task

    task = kb_task("t-fridge", "close_open_refrigerator", "Refrigerator", "Refrigerator", "floor",
                   articulations=[("Refrigerator", "door", "open")])
    spec = build_scene(task, seed=0, settings=Settings(build={"clutter": 1}), out_dir=tmp_path)
    st = plan_from_kb(task.id, task.hazard_class, dict(spec.bindings), spec=spec).subtasks[0]
    model, data, spec = load_scene(tmp_path)
    ep = Episode(model, data, spec)
    fridge = next(o for o in spec.objects if o.asset.category == "Refrigerator")
    named = next(t.joint for t in st.reward.terms if t.kind == "joint")
    door = max((j for j in fridge.joint_states if j.label == "door"), key=lambda j: abs(data.joint(j.name).qpos[0]))
    assert abs(data.joint(named).qpos[0]) < 0.01 < abs(data.joint(door.name).qpos[0])  # the scene this guards
    moved, note = retarget_joints(ep, st)
    term = next(t for t in moved.reward.terms if t.kind == "joint")
    assert (term.joint, term.target) == (door.name, door.closed_value) and named in note
    assert [t.kind for t in moved.reward.terms] == [t.kind for t in st.reward.terms]
    assert retarget_joints(ep, moved) == (moved, "")  # nothing left to move


def test_reward_code_mode_runs_the_sandbox_and_matches_the_spec(at_door):
    """learn.reward_mode = "code": the same sub-task, its reward rendered as code and run in the
    sandbox, gives the spec's rewards step for step; bad code fails before any training."""
    from anomalygen.skills.learned.reward import spec_to_code
    from anomalygen.skills.learned.sac_subtask import snapshot
    from anomalygen.skills.learned.sandbox import RewardCodeError
    from anomalygen.skills.learned.subtask_env import SubTaskEnv

    ep, st, plan = at_door
    drv = ep.driver
    snap = snapshot(drv.model, drv.data)
    as_code = st.model_copy(update={"reward": st.reward.model_copy(update={"mode": "code", "code": spec_to_code(st.reward)})})
    spec_env = SubTaskEnv(drv.model, snap, ep.spec, st, plan.bindings, start_noise=0.0)
    code_env = SubTaskEnv(drv.model, snap, ep.spec, as_code, plan.bindings, start_noise=0.0)
    assert code_env.readout._code is not None and spec_env.readout._code is None
    spec_env.reset(seed=0)
    code_env.reset(seed=0)
    for _ in range(5):
        a = _push_action(spec_env, spec_env.data)
        _, r_spec, *_ = spec_env.step(a)
        _, r_code, *_ = code_env.step(a)
        assert r_code == pytest.approx(r_spec, rel=1e-9, abs=1e-9)
    code_env.close()
    bad = st.model_copy(update={"reward": st.reward.model_copy(update={"mode": "code", "code": "def compute_reward(state):\n    return state['nope']\n"})})
    with pytest.raises(RewardCodeError):
        SubTaskEnv(drv.model, snap, ep.spec, bad, plan.bindings)
