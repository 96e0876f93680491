"""The LLM agent end to end: the scripted OpenAI-compatible server (real HTTP) and the bundled tiny GGUF
drive it through the skill-level env to the referee's verdict; a bad reply is repaired with the error,
and one that stays bad fails that step only."""

from __future__ import annotations

import json

import pytest

import anomalygen
from anomalygen.agents import LLMAgent
from anomalygen.config import Settings
from support.fixtures import llm_config_for
from support.openai_server import text

GOOD = {"problem": "The pot's handle sticks out over the counter's edge: a child could pull it down",
        "target_object": "kitchenpot_0", "hazard_class": "turn_pan_handle_inward", "skill": "fix",
        "object": "kitchenpot_0"}


def _user(req) -> str:
    return next(m["content"] for m in req["messages"] if m["role"] == "user")


def responder(req):
    """Turn 1: a name not in the scene, then (repaired) a fix; turn 2: a call missing its destination,
    however often it is asked; turn 3: done."""
    user = _user(req)
    repaired = any(m["role"] == "assistant" for m in req["messages"])
    if "What you did so far" not in user:
        return text(json.dumps({**GOOD, "object": "flux_capacitor_0"} if not repaired else GOOD))
    if "not a valid call" not in user:
        return text(json.dumps({"problem": "The pot", "skill": "pick_place", "object": "kitchenpot_0"}))
    return text(json.dumps({"problem": "nothing", "skill": "done"}))


@pytest.mark.slow
def test_the_llm_agent_runs_against_the_scripted_server_and_a_bad_reply_fails_one_step(
        skill_scenes, scripted_server, tmp_path):
    task, folder = skill_scenes["pan"]
    srv = scripted_server(responder)
    settings = Settings()
    settings.llm = llm_config_for(srv, tmp_path, cache=False, repair_retries=1)
    agent = LLMAgent(settings=settings)
    env = anomalygen.make_env(folder, level="skills", observe=agent.observe, settings=settings)
    obs, info = env.reset(seed=0)
    scene_text = obs["scene_text"]
    agent.reset(obs, info)
    infos = []
    while True:
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        agent.result(info)
        infos.append(info)
        if terminated or truncated:
            break
    assert [i["call"] for i in infos] == ["fix(kitchenpot_0, turn_pan_handle_inward)", None, "done"]
    assert infos[0]["executed"] and infos[0]["error"] is None
    assert "no valid reply" in infos[1]["error"] and "pick_place needs destination" in infos[1]["error"]
    assert terminated and info["verdict"].status == "resolved"
    # 2 requests for the first turn (the bad name went back with the error), 2 for the second (one repair), 1
    assert len(srv.requests) == 5
    assert "flux_capacitor_0" in srv.requests[1]["messages"][-1]["content"]
    first = srv.requests[0]
    system = next(m["content"] for m in first["messages"] if m["role"] == "system")
    assert "safety sense of a household robot" in system and "pick_place(object, destination" in system
    assert "Known hazard classes" in system and "kitchenpot_0" in _user(first)
    # what the model is shown of the scene is the env's observation (checked for leaks there), and no class id
    assert _user(first).startswith(scene_text) and task.hazard_class not in _user(first)
    assert [(h.target_object, h.hazard_class) for h in agent.detections()] == [("kitchenpot_0", "turn_pan_handle_inward")]


@pytest.mark.slow
@pytest.mark.gguf
def test_the_llm_agent_runs_on_the_bundled_gguf(skill_scenes):
    """The mechanics on the tiny model: grammar-constrained replies name real objects and skills, or the
    step fails with the reason; the episode ends judged either way."""
    from anomalygen.config import LLMConfig

    settings = Settings()
    settings.llm = LLMConfig(backend="llamacpp", cache=False, max_tokens=120, repair_retries=0, n_ctx=8192)
    agent = LLMAgent(settings=settings)
    env = anomalygen.make_env(skill_scenes["free"][1], level="skills", observe=agent.observe, max_calls=2,
                              settings=settings)
    obs, info = env.reset(seed=0)
    agent.reset(obs, info)
    done = False
    while not done:
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        agent.result(info)
        assert (info["call"] is None) != (info["error"] is None) or info["executed"]
        done = terminated or truncated
    assert info["verdict"].status in ("no_action_needed", "acted_on_safe")
    assert agent.client.usage.requests >= 1


def test_with_a_vision_endpoint_the_agent_shows_the_front_camera_too(skill_scenes, scripted_server, tmp_path):
    srv = scripted_server([text(json.dumps({"problem": "nothing", "skill": "done"}))])
    settings = Settings()
    settings.llm = llm_config_for(srv, tmp_path, cache=False, vision=True)
    agent = LLMAgent(settings=settings)
    env = anomalygen.make_env(skill_scenes["pan"][1], level="skills", observe=agent.observe, settings=settings,
                              width=64, height=48)
    obs, info = env.reset(seed=0)
    agent.reset(obs, info)
    assert agent.act(obs).text() == "done" and agent.detections() == []
    (user,) = [m["content"] for m in srv.requests[0]["messages"] if m["role"] == "user"]
    kinds = [part["type"] for part in user]
    assert kinds == ["text", "image_url"] and user[1]["image_url"]["url"].startswith("data:image/png;base64,")
    env.close()
