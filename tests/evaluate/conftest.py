"""A small hand-built run (every artefact made with the schema classes) for the evaluate/report tests."""

from __future__ import annotations

import numpy as np
import pytest

from anomalygen.runfolder import RunFolder, atomic_write_bytes, write_jsonl, write_model
from anomalygen.schema import (
    AssetRef,
    BrainstormMode,
    Detection,
    Engine,
    FixOutcome,
    HazardCategory,
    HazardManifest,
    HazardOutcome,
    Hypothesis,
    LLMUsage,
    ManifestHazard,
    ObjectRole,
    PlacedObject,
    Provenance,
    Scenario,
    SceneSpec,
    SkillMethod,
    SkillResult,
    StageRecord,
    SubTaskResult,
    TaskProposal,
)

TASKS = [
    ("pill_on_floor", "A pill lies on the living room floor where a toddler crawls.", HazardCategory.CHILD_SAFETY,
     "remove_choking_hazards", "pill"),
    ("knife_at_edge", "A kitchen knife sticks out over the counter edge.", HazardCategory.HOUSEHOLD_HAZARD,
     "store_sharp_objects", "knife"),
    ("fridge_open", "The fridge door was left open and food is warming up.", HazardCategory.HYGIENE,
     "close_open_refrigerator", "refrigerator"),
    ("bleach_low_shelf", "A bottle of bleach stands on a low shelf within a child's reach.", HazardCategory.CHILD_SAFETY,
     "keep_chemicals_from_children", "bottle"),
    ("towel_on_stove", "A dish towel hangs over a hot stove burner.", HazardCategory.HOUSEHOLD_HAZARD,
     "switch_off_appliance", "stove"),
]
# The rank at which the detection names the truth hazard (None = never; the other ranks claim a decoy),
# the robot's own check and the referee's verdict per task: the two verdicts disagree on the knife.
HIT_RANKS = {"pill_on_floor": 1, "knife_at_edge": 2, "fridge_open": 1, "bleach_low_shelf": None, "towel_on_stove": 3}
SUCCESS = {"pill_on_floor": True, "knife_at_edge": True, "fridge_open": False, "bleach_low_shelf": True, "towel_on_stove": False}
RESOLVED = {"pill_on_floor": True, "knife_at_edge": False, "fridge_open": False, "bleach_low_shelf": True, "towel_on_stove": False}
DECOY = ("decoy_0", "reduce_tripping_hazards")


def manifest(task: TaskProposal, *, hazard_free: bool = False) -> HazardManifest:
    """truth.json of a synthetic scene: the task's class on ``<asset>_0`` (nothing when hazard-free)."""
    hazards = [] if hazard_free else [ManifestHazard(hazard_class=task.hazard_class, object=f"{task.target_asset}_0",
                                                     category=task.target_asset, severity=0.5, variable="$hazard")]
    return HazardManifest(scene_id=task.id, task_id=task.id, hazards=hazards)


def outcome(task: TaskProposal, resolved: bool) -> FixOutcome:
    return FixOutcome(hazards=[HazardOutcome(hazard_class=task.hazard_class, object=f"{task.target_asset}_0",
                                             resolved=resolved)], resolved=resolved)


def _png(rgb: np.ndarray) -> bytes:
    import io

    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(rgb).save(buf, format="PNG")
    return buf.getvalue()


def _render(i: int) -> np.ndarray:
    """A distinct synthetic 'scene': floor colour and a box position vary with i."""
    img = np.zeros((120, 160, 3), dtype=np.uint8)
    img[:] = (40 + 40 * i, 90, 200 - 30 * i)
    img[30 + 10 * i : 60 + 10 * i, 20 + 20 * i : 70 + 20 * i] = (250, 220, 30)
    return img


def _video(path, i: int) -> None:

    frames = np.stack([np.roll(_render(i), 4 * f, axis=1) for f in range(8)])
    path.parent.mkdir(parents=True, exist_ok=True)
    import imageio

    imageio.mimwrite(path, list(frames), fps=8, macro_block_size=1)


def build_synthetic_run(root, *, stages=("brainstorm", "build", "detect", "learn")) -> RunFolder:
    run = RunFolder.create(root)
    tasks = [
        TaskProposal(
            id=tid, name=tid, explanation=desc, description=desc, category=cat, hazard_class=cls,
            target_asset=asset, scenario=Scenario(hazard_object=asset, room="kitchen", placement="floor"),
            provenance=Provenance(engine=Engine.KNOWLEDGE, mode=BrainstormMode.BRAINSTORM, seed=0),
        )
        for tid, desc, cat, cls, asset in TASKS
    ]
    if "brainstorm" in stages:
        write_jsonl(run.tasks_path, tasks)
    if "build" in stages:
        for i, t in enumerate(tasks):
            obj = PlacedObject(name=f"{t.target_asset}_0", asset=AssetRef(asset_id=t.target_asset, category=t.target_asset),
                               role=ObjectRole.HAZARD, size=0.1, pos=[0.0, 0.0, 0.0])
            write_model(run.scene_dir(t.id) / "scene.json",
                        SceneSpec(scene_id=t.id, task_id=t.id, room="kitchen", seed=0, objects=[obj]))
            atomic_write_bytes(run.scene_dir(t.id) / "render_front.png", _png(_render(i)))
            write_model(run.scene_dir(t.id) / "truth.json", manifest(t))
    if "detect" in stages:
        dets = []
        for t in tasks:
            hyps = [Hypothesis(rank=r, problem=f"problem {r}", solution="fix it",
                               target_object=f"{t.target_asset}_0" if r == HIT_RANKS[t.id] else DECOY[0],
                               hazard_class=t.hazard_class if r == HIT_RANKS[t.id] else DECOY[1]) for r in (1, 2, 3)]
            dets.append(Detection(task_id=t.id, scene_id=t.id, detector="rules", hypotheses=hyps))
        write_jsonl(run.detections_path, dets)
    if "learn" in stages:
        for i, t in enumerate(tasks):
            folder = run.skill_dir(t.id, 0)
            _video(folder / "video.mp4", i)
            write_model(folder / "result.json", SkillResult(
                task_id=t.id, seed=0, success=SUCCESS[t.id], video="video.mp4", outcome=outcome(t, RESOLVED[t.id]),
                subtasks=[SubTaskResult(id="s1", method=SkillMethod.PRIMITIVE, success=True),
                          SubTaskResult(id="s2", method=SkillMethod.SAC, success=SUCCESS[t.id])]))
    with run.update_manifest() as m:
        for s in stages:
            m.stages[s] = StageRecord(started="2026-01-01T00:00:00Z", finished="2026-01-01T00:00:05Z", wall_s=5.0, done=5)
        m.llm_usage = LLMUsage(requests=3, prompt_tokens=1200, completion_tokens=300)
    return run


@pytest.fixture
def synthetic_run(tmp_path):
    return build_synthetic_run(tmp_path / "synth")
