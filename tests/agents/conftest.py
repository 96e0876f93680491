"""Scenes the skill-level env is tested on: brainstormed tasks (their own words), built once per module.

``pan``: a pot with its handle out over the counter's edge (one hazard, one fix: turn it inward), in a
run folder (``tasks.jsonl``, ``scenes/<task_id>/``) so the pipeline's own stages can run on it too;
``free``: the second task's scene built hazard-free.
"""

from __future__ import annotations

import pytest

from support.fixtures import scripted_server  # noqa: F401  (the scripted LLM server, for the LLM agent)


@pytest.fixture(scope="session")
def skill_scenes(tmp_path_factory):
    from anomalygen.brainstorm.knowledge_engine import KnowledgeEngine
    from anomalygen.config import Settings
    from anomalygen.runfolder import RunFolder, write_jsonl
    from anomalygen.scene.build import build_scene

    pan, other = KnowledgeEngine(seed=0, agents=2, rounds=1).run(2)
    assert pan.hazard_class == "turn_pan_handle_inward"
    # What the tests call on is named, not left to draws keyed by the task's id (its words): a hair
    # dryer whose switch is pressed, and no second hazard from the judgement mix.
    scenario = pan.scenario.model_copy(update={"co_objects": [*pan.scenario.co_objects, "hair_dryer"]})
    pan = pan.model_copy(update={"scenario": scenario})
    single = Settings(build={"multi_hazard": 0.0})
    root = tmp_path_factory.mktemp("skill_scenes")
    run = RunFolder.create(root / "run", settings=single)
    write_jsonl(run.tasks_path, [pan])
    build_scene(pan, seed=0, settings=single, out_dir=run.scene_dir(pan.id))
    free = root / "free" / other.id
    build_scene(other, seed=0, settings=Settings(), out_dir=free, hazard_free=True)
    return {"pan": (pan, run.scene_dir(pan.id)), "free": (other, free), "run": run}
