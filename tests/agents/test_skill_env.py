"""The skill-level env on real built scenes: Gymnasium's checker, invalid calls that cost a step and
say why, the detector's reading as the observation and nothing of the answer key before the end, a
call run by the robot's skills, and our pipeline as an agent, bit for bit the pipeline."""

from __future__ import annotations

import json

import numpy as np
import pytest

import anomalygen
from anomalygen.agents.skill_env import ENV_ID, SkillEnv
from support.ids import assert_no_task_words


def _jsonable(x):
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_jsonable(v) for v in x]
    return x


def test_passes_gymnasiums_env_checker(skill_scenes):
    from gymnasium.utils.env_checker import check_env

    _, folder = skill_scenes["pan"]
    env = SkillEnv(folder, max_calls=3, width=96, height=72)
    check_env(env)
    env.close()


def test_registered_with_gymnasium(skill_scenes):
    import gymnasium as gym

    env = gym.make(ENV_ID, scene_dir=skill_scenes["free"][1], observe=("objects",))
    obs, info = env.reset(seed=0)
    assert env.observation_space.contains(obs) and info["max_calls"] == env.spec.max_episode_steps
    env.close()


def test_an_invalid_call_costs_a_step_says_why_and_never_raises(skill_scenes):
    _, folder = skill_scenes["pan"]
    env = anomalygen.make_env(folder, level="skills", max_calls=6, observe=("objects",))
    obs, _ = env.reset(seed=0)
    start = {o["name"]: o["position"] for o in obs["objects"]}
    bad = {
        "put the pot somewhere safe": "not a call",
        None: "not NoneType",
        "x" * 5000: "no call (at most 2000)",
        "pick_place(spaceship_0, counter_0)": "'spaceship_0' is not an object in the scene",
        "turn_inward(counter_0)": "fixed in place",
    }
    for i, (action, reason) in enumerate(bad.items(), start=1):
        obs, reward, terminated, truncated, info = env.step(action)
        assert reason in info["error"] and info["call"] is None and info["executed"] == []
        assert (terminated, truncated, reward, info["calls_left"]) == (False, False, 0.0, 6 - i)
        assert {o["name"]: o["position"].tolist() for o in obs["objects"]} == {k: v.tolist() for k, v in start.items()}
        assert "verdict" not in info
    obs, _, terminated, truncated, info = env.step({"skill": "switch_off", "args": {"object": "kitchenpot_0"}})
    assert not terminated and truncated  # the sixth call is the last: the budget ends the episode, judged
    assert "has no knob, switch or tap" in info["error"] and info["verdict"].status == "unresolved"
    env.close()


def test_it_shows_the_detectors_reading_and_nothing_of_the_answer_key_before_the_end(skill_scenes):
    from anomalygen.detect.observation import observation_text

    task, folder = skill_scenes["pan"]
    env = anomalygen.make_env(folder, level="skills", max_calls=4, width=160, height=120)
    obs, info = env.reset(seed=0)
    graph = env.unwrapped.graph()
    assert obs["scene_text"] == observation_text(graph)
    assert [o["name"] for o in obs["objects"]] == [o.name for o in graph.objects]
    pot = next(o for o in obs["objects"] if o["name"] == "kitchenpot_0")
    assert pot["movable"] == 1 and {p["label"] for p in pot["parts"]} == {"lid"}
    assert obs["image"].shape == (120, 160, 3) and obs["image"].std() > 5
    assert env.observation_space.contains(obs)
    infos = [info]
    for action in ("wait", "close(kitchenpot_0, lid)"):
        obs, _, terminated, truncated, info = env.step(action)
        assert not (terminated or truncated) and info["error"] is None
        infos.append(info)
    assert infos[1]["call"] == "wait" and infos[2]["executed"]
    other = anomalygen.make_env(skill_scenes["free"][1], level="skills", observe=())
    assert other.reset(seed=0)[1]["skills"] == infos[0]["skills"]  # the vocabulary: the same in every scene
    assert_no_task_words(task, {
        "observation": _jsonable({k: v for k, v in obs.items() if k != "image"}),
        "info before the end": json.loads(json.dumps([{k: v for k, v in i.items() if k != "skills"} for i in infos])),
    })
    assert all("verdict" not in i and "is_success" not in i for i in infos)
    obs, _, terminated, truncated, info = env.step("done")
    assert terminated and not truncated
    assert info["verdict"].status == "unresolved" and info["is_success"] is False  # the handle is still out
    env.close()
    other.close()


@pytest.mark.slow
def test_a_call_is_carried_out_by_the_robots_skills_and_judged(skill_scenes):
    _, folder = skill_scenes["pan"]
    env = anomalygen.make_env(folder, level="skills", observe=("objects",))
    env.reset(seed=0)
    _, _, _, _, info = env.step("turn_inward(kitchenpot_0)")
    assert info["error"] is None and [r["id"] for r in info["executed"]] == ["s1_rotate_inward"]
    assert info["executed"][0]["success"] and "not has_state: yes" in info["executed"][0]["detail"]
    _, _, terminated, _, info = env.step("done")
    assert terminated and info["verdict"].status == "resolved" and info["is_success"] is True
    env.close()


@pytest.mark.slow
def test_the_pipeline_agent_is_the_pipeline_bit_for_bit(skill_scenes, tmp_path):
    """detect, plan and learn on the scene give the very final state the Pipeline agent leaves."""
    from anomalygen.agents import Pipeline
    from anomalygen.config import Settings
    from anomalygen.stages import stage
    from anomalygen.world.state import get_state

    task, folder = skill_scenes["pan"]
    run = skill_scenes["run"]
    settings = Settings(quiet=True, learn={"video": False})
    for name in ("detect", "plan", "learn"):
        stage(name).run(run, settings)
    saved = np.load(run.skill_dir(task.id, 0) / "final_state.npz")

    agent = Pipeline(settings=settings)
    env = anomalygen.make_env(folder, level="skills", observe=agent.observe, settings=settings)
    obs, info = env.reset(seed=0)
    agent.reset(obs, info)
    calls = []
    while True:
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        calls.append(info["call"])
        if terminated or truncated:
            break
    assert calls == ["fix(kitchenpot_0, turn_pan_handle_inward)", "wait", "done"]
    base = env.unwrapped
    assert np.array_equal(get_state(base.model, base.data), saved["state"])
    assert info["verdict"].status == "resolved"
    env.close()
