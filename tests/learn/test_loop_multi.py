"""The whole loop on a two-hazard scene, against the hidden truth: the robot finds both hazards from
perception, plans a fix for each, executes them in the real simulator, and the referee checks each."""

from __future__ import annotations

import pytest

from anomalygen.schema import Detection, HazardManifest, Plan, SkillResult

pytestmark = pytest.mark.slow


def test_two_hazards_are_both_found_planned_and_judged(tmp_path):
    from anomalygen.config import Settings
    from anomalygen.detect.stage import run_stage as detect
    from anomalygen.learn.stage import run_stage as learn
    from anomalygen.plan.stage import run_stage as plan
    from anomalygen.runfolder import RunFolder, read_model, write_jsonl
    from anomalygen.scene.stage import run_stage as build
    from anomalygen.schema import TaskProposal

    task = TaskProposal(id="m", name="n", explanation="e", description="d", category="child_safety",
                        hazard_class="close_open_furniture", target_asset="Dishwasher",
                        scenario=dict(hazard_object="Dishwasher", room="kitchen", placement="floor"),
                        articulations=[dict(object="Dishwasher", part="door", function="closes the compartment",
                                            initial_state="open", target_state="closed")],
                        provenance=dict(engine="knowledge", mode="brainstorm"))
    run = RunFolder.create(tmp_path / "r")
    write_jsonl(run.tasks_path, [task])
    settings = Settings(quiet=True, workers=1, build={"multi_hazard": 1.0, "hazard_free": 0.0, "clutter": 1})
    settings.learn.video = False
    assert build(run, settings).done == 1
    truth = read_model(run.scene_dir("m") / "truth.json", HazardManifest)
    assert len(truth.hazards) == 2, truth.hazards
    assert detect(run, settings).done == 1 and plan(run, settings).done == 1 and learn(run, settings).done == 1

    det = next(Detection.model_validate_json(line) for line in run.detections_path.read_text().splitlines())
    named = {h.target_object for h in det.hypotheses}
    assert {z.object for z in truth.hazards} <= named  # both found, from perception alone
    p = read_model(run.plan_path("m"), Plan)
    touched = {str(st.params.get("object")) for st in p.subtasks}
    assert {z.object for z in truth.hazards} <= touched  # a fix for each
    assert read_model(run.skill_dir("m", 0) / "result.json", SkillResult).outcome is None
    # the referee's verdict, after the robot: the physical state, released and settled. Each hazard is
    # resolved exactly when no class fires on its object in the scene graph the referee judged
    from anomalygen.knowledge import load_kb
    from anomalygen.referee import load_verdict
    from anomalygen.referee.stage import run_stage as judge
    from anomalygen.schema import SceneGraph
    from anomalygen.truth.manifest import class_matches

    assert judge(run, settings).done == 1
    verdict = load_verdict(run, "m", 0)
    assert len(verdict.hazards) == 2 and verdict.judged_from == "state"
    final = read_model(run.skill_dir("m", 0) / "judged_graph.json", SceneGraph)
    still = {o for _, o, _ in class_matches(final, load_kb())}
    for h in verdict.hazards:
        assert (h.object in still) == bool(h.still_firing)
        assert not h.resolved or h.object not in still
    assert verdict.resolved == (all(h.resolved for h in verdict.hazards) and not verdict.new_hazards)
