"""What the robot reads of a real built scene carries no answer key and none of the task's words:
the perceived spec, the scene graph, scene.xml, and the public env's spec, observation layout and info
until its episode ends (then the referee's verdict)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import anomalygen
from anomalygen.config import Settings
from anomalygen.runfolder import read_model
from anomalygen.schema import SceneSpec
from anomalygen.world.perception import (
    UNKNOWN_ROLE,
    load_perceived_scene,
    load_perceived_spec,
    load_scene_graph,
)
from support.ids import assert_no_task_words

OBS_KEYS = {"robot_qpos", "robot_qvel", "ee_pos", "ee_quat", "object_pos", "object_quat", "object_joints", "suction"}


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    """A brainstormed task (its own words, not a test's) and its built scene."""
    from anomalygen.brainstorm.knowledge_engine import KnowledgeEngine
    from anomalygen.scene.build import build_scene

    task = KnowledgeEngine(seed=0, agents=2, rounds=1).run(2)[1]
    folder = tmp_path_factory.mktemp("perceived") / task.id
    build_scene(task, seed=0, settings=Settings(), out_dir=folder)
    return task, folder


def test_perceived_spec_and_graph_carry_no_answer_key_or_task_words(scene):
    task, folder = scene
    spec = load_perceived_spec(folder)
    full = read_model(folder / "scene.json", SceneSpec)
    assert full.bindings and full.validation is not None  # the builder's file has them ...
    assert spec.bindings == {} and spec.task_id == "" and spec.validation is None  # ... the robot's copy not
    assert {o.role for o in spec.objects} == {UNKNOWN_ROLE}
    assert [o.name for o in spec.objects] == sorted(o.name for o in full.objects)
    model, data, live = load_perceived_scene(folder)
    assert live == spec and model.nbody > len(spec.objects)
    model_names = [model.sensor(i).name for i in range(model.nsensor)] + [model.camera(i).name for i in range(model.ncam)]
    assert_no_task_words(task, {
        "perceived spec": spec.model_dump(mode="json"),
        "scene graph": load_scene_graph(folder).model_dump(mode="json"),
        "sensor and camera names": model_names,
    })


def test_make_env_shows_no_answer_key_before_the_end_and_the_verdict_at_it(scene):
    """The public env (``anomalygen.make_env``): its spec, observation layout and every info before the
    episode ends carry no bindings, roles, validation or task words; the last info holds the referee's
    verdict on this scene (the robot did nothing, so nothing is resolved)."""
    from anomalygen.schema import Verdict

    task, folder = scene
    env = anomalygen.make_env(folder, horizon=5)
    base = env.unwrapped
    assert base.scene == load_perceived_spec(folder)
    obs, info = env.reset(seed=0)
    infos, ends = [info], [False]
    while not ends[-1]:
        obs, _, terminated, truncated, info = env.step(np.zeros(7))
        infos.append(info)
        ends.append(terminated or truncated)
    assert ends == [False] * 5 + [True]
    assert set(base.obs_layout) == OBS_KEYS and obs.size == env.observation_space.shape[0]
    assert all(info == {} for info in infos[:-1])  # no success to claim: the env has no answer key
    assert_no_task_words(task, {
        "env scene": base.scene.model_dump(mode="json"),
        "env layout": {"layout": sorted(base.obs_layout), "objects": base.object_names},
        "env info before the end": json.loads(json.dumps(infos[:-1])),
    })
    end = infos[-1]
    assert set(end) == {"verdict", "is_success", "own_check"} and end["own_check"] is None
    verdict = end["verdict"]
    assert isinstance(verdict, Verdict) and verdict.task_id == task.id and verdict.seed is None
    assert verdict.status in ("unresolved", "no_action_needed") and end["is_success"] is verdict.resolved is False
    env.close()
