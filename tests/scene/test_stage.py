"""The build stage: resumable, failures recorded with one-line reasons, contact sheet written."""

import pytest

from anomalygen.config import Settings
from anomalygen.runfolder import RunFolder, read_model, write_jsonl
from anomalygen.scene.stage import run_stage
from anomalygen.schema import HazardManifest, SceneSpec

from .conftest import TASKS, make_task


def test_build_resume_and_failure_reason(tmp_path):
    run = RunFolder.create(tmp_path / "run")
    # loads (a placement the schema knows), but a banana has no interior to put the battery in
    bad = make_task("t-bad", "remove_choking_hazards", "Safe", "button_battery", "inside:banana")
    write_jsonl(run.tasks_path, [TASKS["floor"], bad])
    settings = Settings(workers=1, quiet=True, build={"clutter": 0})
    first = run_stage(run, settings)
    assert (first.done, first.failed) == (1, 1)
    reason = run.errors("build")[0].error
    assert "inside:banana" in reason and "\n" not in reason
    assert read_model(run.scene_dir("t-floor") / "scene.json", SceneSpec).validation.ok
    assert (run.scenes_dir / "contact_sheet.png").stat().st_size > 1000
    second = run_stage(run, settings, only=["t-floor"])
    assert (second.done, second.skipped) == (0, 1)


def truth(scene_dir):
    return read_model(scene_dir / "truth.json", HazardManifest)


@pytest.mark.slow
def test_knowledge_engine_tasks_build_end_to_end(tmp_path):
    """A handful of real knowledge-engine proposals build into valid scenes (>= 4 of 5)."""
    from anomalygen.brainstorm.knowledge_engine import generate

    run = RunFolder.create(tmp_path / "run")
    write_jsonl(run.tasks_path, generate(5, seed=3))
    summary = run_stage(run, Settings(workers=1, quiet=True))
    assert summary.done >= 4, summary.errors
    from anomalygen.scene.stage import revalidate_run

    rechecked = revalidate_run(run)
    assert len(rechecked) == summary.done
    assert all(reason is None for reason in rechecked.values()), rechecked
    for task in run.load_tasks():
        if task.id in summary.errors:
            assert "\n" not in summary.errors[task.id]
            continue
        spec = read_model(run.scene_dir(task.id) / "scene.json", SceneSpec)
        assert spec.validation.ok
        if not spec.bindings:  # one of the mix's hazard-free scenes: nothing bound, the task's hazard absent
            assert task.hazard_class not in {h.hazard_class for h in truth(run.scene_dir(task.id)).hazards}
            continue
        assert spec.bindings["$hazard"]
