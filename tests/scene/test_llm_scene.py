"""``build --engine llm``: sizes and positions come from the LLM's replies or from recorded repairs.

A scripted OpenAI-compatible server plays the LLM of the paper's scene stage: it lists auxiliary
objects by loose names (one of them matches nothing in the catalogue), then gives sizes and positions
with deliberate mistakes (a safe three metres large, the hazard outside the unit square). The built
scene must use every number that was acceptable, and its validation report must name each repair.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from anomalygen.config import Settings
from anomalygen.runfolder import RunFolder, read_model, write_jsonl
from anomalygen.scene.hints import SceneHints
from anomalygen.scene.layout import REGION_ORIGIN, REGION_SIZE
from anomalygen.scene.stage import run_stage
from anomalygen.schema import SceneSpec
from support.fixtures import llm_config_for
from support.openai_server import text

from .conftest import TASKS

AUXILIARIES = {"objects": [
    {"name": "tissues", "description": "a small cardboard box of paper tissues"},
    {"name": "time machine", "description": "a brass device that travels through the centuries"},
]}
LAYOUT = {"objects": [
    {"name": "Safe", "size_m": 3.0, "x": 0.75, "y": 0.7},             # too large: clamped to the KB's 0.6 m
    {"name": "button battery", "size_m": 0.02, "x": 1.4, "y": 0.35},  # loose name; outside the square
    {"name": "storage_box", "size_m": 0.4, "x": 0.2, "y": 0.8},
    {"name": "tissue_box", "size_m": 0.22, "x": -0.6, "y": 0.5},
]}


def responder(body):
    user = body["messages"][-1]["content"]
    return text(json.dumps(AUXILIARIES if "List up to" in user else LAYOUT))


def test_llm_scene_engine_builds_from_the_replies_and_records_repairs(scripted_server, tmp_path):
    srv = scripted_server(responder)
    settings = Settings(quiet=True, workers=1, llm=llm_config_for(srv, tmp_path, cache=False), build={"engine": "llm", "clutter": 2})
    run = RunFolder.create(tmp_path / "run", settings=settings)
    task = TASKS["floor"].model_copy(deep=True)
    task.scenario.container = "storage_box"  # the LLM sizes it (the class's first container is the safe)
    write_jsonl(run.tasks_path, [task])
    summary = run_stage(run, settings)
    assert summary.done == 1 and summary.failed == 0, summary.errors
    assert len(srv.requests) == 2
    folder = run.scene_dir(task.id)
    spec = read_model(folder / "scene.json", SceneSpec)
    hints = read_model(folder / "llm_layout.json", SceneHints)
    by_cat = {o.asset.category: o for o in spec.objects}

    # sizes: taken from the replies, or clamped to the knowledge base's range with a record
    assert abs(by_cat["button_battery"].size - 0.02) < 1e-6
    assert abs(by_cat["Safe"].size - 0.6) < 1e-6
    assert abs(by_cat["storage_box"].size - 0.4) < 1e-6
    checks = {c.name: c for c in spec.validation.checks}
    assert "clamped to 0.600" in checks["size:Safe"].detail and checks["size:Safe"].value == 3.0

    # positions: the battery's x was moved into the square (recorded), then used as the floor spot
    assert "outside the unit square" in checks["position:button_battery"].detail
    assert hints.positions["button_battery"] == (1.0, 0.35)
    battery = next(o for o in spec.objects if o.asset.category == "button_battery")
    placed = checks[f"position:{battery.name}"]
    want = REGION_ORIGIN[:2] + np.array([1.0, 0.35]) * REGION_SIZE[:2]
    if "moved to" in placed.detail:  # the solver had to repair an overlap, and said where to
        assert placed.value > 0
    else:
        assert np.linalg.norm(np.array(battery.pos[:2]) - want) < 0.05
    safe = next(o for o in spec.objects if o.asset.category == "Safe")
    assert f"position:{safe.name}" in checks

    # auxiliaries: the retrieved tissue box dresses the scene, the unknown one is left out and noted
    assert hints.auxiliaries == ["tissue_box"] and abs(by_cat["tissue_box"].size - 0.22) < 1e-6
    assert "left out" in checks["auxiliary:time machine"].detail
    assert any(m.written == "tissues" and m.grounded == "tissue_box" and m.method == "retrieval" for m in hints.grounding)
    assert spec.validation.ok


@pytest.mark.slow
@pytest.mark.gguf
def test_tiny_gguf_runs_the_llm_scene_engine(tmp_path):
    """The bundled 135M model proves the mechanics: the scene is built from its (checked) numbers, or
    the one item fails with a one-line reason; either way nothing else breaks."""
    settings = Settings(
        quiet=True, workers=1, build={"engine": "llm", "clutter": 1},
        llm={"backend": "llamacpp", "cache_path": str(tmp_path / "c.sqlite"), "repair_retries": 1, "max_tokens": 160},
    )
    run = RunFolder.create(tmp_path / "run", settings=settings)
    task = TASKS["floor"].model_copy(deep=True)
    task.scenario.container = "storage_box"  # the LLM sizes it (the class's first container is the safe)
    write_jsonl(run.tasks_path, [task])
    summary = run_stage(run, settings)
    assert summary.done + summary.failed == 1
    folder = run.scene_dir(task.id)
    if summary.done:
        hints = read_model(folder / "llm_layout.json", SceneHints)
        spec = read_model(folder / "scene.json", SceneSpec)
        assert spec.validation.ok and hints.model
        names = {c.name for c in spec.validation.checks}
        # every task object's size and position is either the model's or a recorded correction
        for cat in ("Safe", "button_battery"):
            assert cat in hints.sizes or f"layout:{cat}" in names
    else:
        [reason] = summary.errors.values()
        assert "\n" not in reason and reason
