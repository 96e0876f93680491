"""The loop table counts a detected hazard whose fix the planner had to leave out, not only planned ones."""

from __future__ import annotations

from anomalygen.evaluate.hazard_table import hazard_table, markdown
from anomalygen.runfolder import RunFolder, write_model
from anomalygen.schema import DroppedFix, HazardManifest, ManifestHazard, Plan, SubTask, SuccessSpec


def test_a_dropped_fix_is_counted_and_named_beside_the_planned_one(tmp_path):
    run = RunFolder.create(tmp_path / "r")
    hazards = [ManifestHazard(hazard_class="close_open_refrigerator", source="intended", object="refrigerator_0",
                              category="Refrigerator", severity=0.5, variable="$target"),
               ManifestHazard(hazard_class="pick_up_floor_litter", source="intended", object="plastic_bag_0",
                              category="plastic_bag", severity=0.4, variable="$hazard")]
    write_model(run.scene_dir("t1") / "truth.json", HazardManifest(scene_id="t1", task_id="t1", hazards=hazards))
    step = SubTask(id="s1", description="close", method="primitive", primitive="push",
                   params={"object": "refrigerator_0"})
    why = "no reachable container for plastic_bag_0 in the scene (wanted: TrashCan)"
    write_model(run.plan_path("t1"), Plan(task_id="t1", source="detected", engine="knowledge", subtasks=[step],
                                          success=SuccessSpec(),
                                          dropped=[DroppedFix(hazard_class="pick_up_floor_litter",
                                                              object="plastic_bag_0", reason=why)]))
    table = hazard_table(run, ["t1"], seeds=1)
    assert table.by_class["close_open_refrigerator"].planned == 1
    assert table.by_class["close_open_refrigerator"].dropped == 0
    litter = table.by_class["pick_up_floor_litter"]
    assert (litter.planned, litter.dropped) == (0, 1) and table.total.dropped == 1
    assert "left out of the plan, nothing in the scene to fix them with: pick_up_floor_litter 1" in markdown(table)
