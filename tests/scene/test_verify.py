"""VLM verification (settings.llm.vision): the render goes to the endpoint; a 'no' fails the scene."""

import json

from anomalygen.config import Settings
from anomalygen.errors import ItemFailed
from anomalygen.runfolder import read_model
from anomalygen.scene.build import build_scene
from anomalygen.schema import SceneSpec
from support.fixtures import llm_config_for, scripted_server  # noqa: F401
from support.openai_server import text

from .conftest import TASKS


def _settings(srv, tmp_path):
    llm = llm_config_for(srv, tmp_path, vision=True).model_dump()
    llm["api_key"] = "sk-test-not-a-real-key"
    return Settings(llm=llm, build={"clutter": 0, "repair_attempts": 0})


def test_vlm_yes_keeps_scene_and_sees_the_render(scripted_server, tmp_path):  # noqa: F811
    srv = scripted_server([text(json.dumps({"fits": True, "reason": "a battery lies on the floor"}))])
    build_scene(TASKS["floor"], seed=0, settings=_settings(srv, tmp_path), out_dir=tmp_path / "ok")
    spec = read_model(tmp_path / "ok" / "scene.json", SceneSpec)
    assert any(c.name == "vlm_verification" and c.passed for c in spec.validation.checks)
    sent = json.dumps(srv.requests[0])
    assert "image" in sent and TASKS["floor"].description in sent


def test_vlm_no_fails_with_its_reason(scripted_server, tmp_path):  # noqa: F811
    srv = scripted_server([text(json.dumps({"fits": False, "reason": "the battery floats above the floor"}))])
    try:
        build_scene(TASKS["floor"], seed=0, settings=_settings(srv, tmp_path), out_dir=tmp_path / "no")
    except ItemFailed as exc:
        assert "VLM rejected the scene: the battery floats" in str(exc)
    else:
        raise AssertionError("a rejected scene must fail")
    assert not (tmp_path / "no" / "scene.json").exists()
