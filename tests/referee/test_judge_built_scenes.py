"""The referee on scenes the real builder made, with the real simulator: end states set by hand (a
robot would have carried the objects there), then released, settled and judged by
``anomalygen.referee.judge``.

Two scenes: a kitchen knife at a counter's edge (its container a tall cabinet with drawers, and a
storage box on the counter), and a pill bottle on a table with a chair in the room.
"""

from __future__ import annotations

import numpy as np
import pytest
from tests.scene.conftest import make_task

from anomalygen.config import Settings
from anomalygen.referee import judge
from anomalygen.world.graph import held_objects, load_scene, scene_graph
from support.moves import cavity_center, hold, put

KNIFE = "kitchen_knife_0"
PILLS = "pill_bottle_0"
# procedural assets: the knife's cases need a cabinet with drawers, and the real cabinets have doors
QUIET_MIX = {"clutter": 0, "near_misses": 0, "multi_hazard": 0.0, "hazard_free": 0.0, "real_assets": False}


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    from anomalygen.scene.build import build_scene

    root = tmp_path_factory.mktemp("judged")
    settings = Settings(build=QUIET_MIX)
    knife = make_task("t-knife-store", "store_sharp_objects", "Table", "kitchen_knife", "counter_edge",
                      container="StorageFurniture", co=("storage_box",))
    pills = make_task("t-pill-chair", "secure_medications", "Table", "pill_bottle", "table", co=("Chair",))
    build_scene(knife, seed=0, settings=settings, out_dir=root / "knife")
    build_scene(pills, seed=0, settings=settings, out_dir=root / "pills")
    return {"knife": root / "knife", "pills": root / "pills"}


def _relations(graph, name):
    return {(r.predicate, r.object) for r in graph.relations if r.subject == name and r.predicate != "near"}


def _named(graph, category):
    return next(o for o in graph.objects if o.category == category)


def _knife_verdict(v):
    (h,) = [h for h in v.hazards if h.object == KNIFE]
    return h


@pytest.mark.slow
def test_the_scenes_as_built_are_unresolved_and_their_truth_says_where_each_hazard_came_from(scenes):
    from anomalygen.referee import load_manifest

    for key, fault in (("knife", KNIFE), ("pills", PILLS)):
        truth = load_manifest(scenes[key])
        assert truth.hazards[0].object == fault and truth.hazards[0].source == "intended"
        model, data, _ = load_scene(scenes[key])
        v = judge(scenes[key], model, data)
        assert v.status == "unresolved" and not v.resolved and v.new_hazards == [] and v.released == []


@pytest.mark.slow
def test_a_knife_under_a_table_is_under_it_not_inside_and_unresolved(scenes):
    model, data, spec = load_scene(scenes["knife"])
    table = _named(scene_graph(model, data, spec), "Table")
    put(model, data, KNIFE, [table.position[0], table.position[1], 0.012], size_z=0.02)
    rel = _relations(scene_graph(model, data, spec), KNIFE)
    assert ("under", table.name) in rel and ("inside", table.name) not in rel and ("on_floor", None) in rel
    v = judge(scenes["knife"], model, data)
    assert v.status == "unresolved" and not _knife_verdict(v).resolved
    assert "keep_sharp_away_from_children on kitchen_knife_0" in v.new_hazards


@pytest.mark.slow
def test_a_pill_bottle_on_a_chair_seat_is_on_the_chair_not_inside_it_and_unresolved(scenes):
    from anomalygen.referee.settle import settled_graph

    model, data, spec = load_scene(scenes["pills"])
    chair = _named(scene_graph(model, data, spec), "Chair")
    put(model, data, PILLS, [chair.position[0], chair.position[1], chair.position[2] + 0.15], size_z=0.07)
    final, _, _ = settled_graph(model, data, spec)  # dropped from above the seat: it lands on it
    rel = _relations(final, PILLS)
    assert ("on", chair.name) in rel and not any(p == "inside" for p, _ in rel)
    v = judge(scenes["pills"], model, data)
    (h,) = v.hazards
    assert v.status == "unresolved" and h.still_firing == ["secure_medications"]


@pytest.mark.slow
def test_an_object_left_held_is_in_nothing_then_released_falls_and_is_unresolved(scenes):
    model, data, spec = load_scene(scenes["knife"])
    box = _named(scene_graph(model, data, spec), "storage_box")
    hold(model, data, spec, KNIFE)
    held = scene_graph(model, data, spec)
    knife = held.get(KNIFE)
    assert knife.held and _relations(held, KNIFE) == set()
    # held inside a box's declared cavity, it is still not "inside" the box: the cup has it
    put(model, data, KNIFE, cavity_center(model, data, spec, box.name, "inside"), yaw=np.pi / 2, size_z=0.02)
    assert not any(p == "inside" for p, _ in _relations(scene_graph(model, data, spec), KNIFE))
    model, data, spec = load_scene(scenes["knife"])
    hold(model, data, spec, KNIFE)  # held in the air beside the robot
    v = judge(scenes["knife"], model, data)
    assert v.released == [KNIFE] and v.status == "unresolved" and not _knife_verdict(v).resolved
    assert held_objects(model, data, spec) == [KNIFE]  # the live state was judged on a copy: the cup still holds it


@pytest.mark.slow
def test_a_knife_off_the_edge_in_a_box_on_the_floor_is_stored_yet_within_a_childs_reach_so_unresolved(scenes):
    model, data, spec = load_scene(scenes["knife"])
    box = _named(scene_graph(model, data, spec), "storage_box")
    put(model, data, box.name, [0.9, 0.2, box.size[2] / 2 + 0.003], size_z=box.size[2])
    put(model, data, KNIFE, cavity_center(model, data, spec, box.name, "inside"), yaw=np.pi / 2, size_z=0.02)
    v = judge(scenes["knife"], model, data)
    h = _knife_verdict(v)
    assert "not inside" not in h.detail  # its own class's success holds: it is in the box
    assert h.still_firing == ["keep_sharp_away_from_children"] and not h.resolved and v.status == "unresolved"


@pytest.mark.slow
def test_a_knife_in_a_closed_high_drawer_is_resolved(scenes):
    model, data, spec = load_scene(scenes["knife"])
    cabinet = next(o for o in spec.objects if o.asset.category == "StorageFurniture")
    bins = [c.name for c in cabinet.cavities if c.name.startswith("drawer")]
    top = max(bins, key=lambda c: cavity_center(model, data, spec, cabinet.name, c)[2])
    center = cavity_center(model, data, spec, cabinet.name, top)
    assert center[2] > 0.6  # above a small child's 0.55 m
    put(model, data, KNIFE, center, size_z=0.02)
    v = judge(scenes["knife"], model, data)
    assert v.status == "resolved" and v.resolved and _knife_verdict(v).detail == "fixed", v
    assert v.new_hazards == [] and v.interventions_on_safe == []


@pytest.mark.slow
def test_make_env_puts_the_referees_verdict_in_info_at_the_end_of_an_episode_only(scenes):
    import anomalygen
    from anomalygen.schema import Verdict

    env = anomalygen.make_env(scenes["knife"], horizon=3)
    env.reset(seed=0)
    infos = []
    for _ in range(3):
        *_, terminated, truncated, info = env.step(np.zeros(env.action_space.shape, dtype=np.float32))
        infos.append((terminated or truncated, info))
    assert [end for end, _ in infos] == [False, False, True]
    assert all("verdict" not in info for _, info in infos[:2])
    end = infos[-1][1]
    assert isinstance(end["verdict"], Verdict) and end["verdict"].status == "unresolved"
    assert end["is_success"] is False and "own_check" in end
    env.close()


@pytest.mark.slow
def test_the_judge_stage_writes_a_verdict_per_run_from_its_saved_final_state(scenes, tmp_path, capsys):
    import json
    import shutil

    from anomalygen.cli import main
    from anomalygen.referee import load_verdict
    from anomalygen.runfolder import RunFolder, write_jsonl, write_model
    from anomalygen.scene_files import FINAL_STATE
    from anomalygen.schema import SkillResult
    from anomalygen.world.state import save_state

    run = RunFolder.create(tmp_path / "run")
    task = make_task("t-knife-store", "store_sharp_objects", "Table", "kitchen_knife", "counter_edge")
    write_jsonl(run.tasks_path, [task])
    shutil.copytree(scenes["knife"], run.scene_dir(task.id))
    for seed, where in ((0, "drawer"), (1, "edge")):  # seed 0 put the knife away, seed 1 left it
        model, data, spec = load_scene(run.scene_dir(task.id))
        if where == "drawer":
            cabinet = next(o for o in spec.objects if o.asset.category == "StorageFurniture")
            bins = [c.name for c in cabinet.cavities if c.name.startswith("drawer")]
            top = max(bins, key=lambda c: cavity_center(model, data, spec, cabinet.name, c)[2])
            put(model, data, KNIFE, cavity_center(model, data, spec, cabinet.name, top), size_z=0.02)
        out = run.skill_dir(task.id, seed)
        save_state(out / FINAL_STATE, model, data)
        write_model(out / "result.json", SkillResult(task_id=task.id, seed=seed, success=True))  # it believes so
    main(["judge", "--run", str(run.root), "--only", task.id, "--json"])
    assert json.loads(capsys.readouterr().out)["done"] == 1
    v0, v1 = load_verdict(run, task.id, 0), load_verdict(run, task.id, 1)
    assert (v0.status, v1.status) == ("resolved", "unresolved") and v0.seed == 0 and v0.judged_from == "state"
    assert (run.skill_dir(task.id, 0) / "judged_graph.json").is_file()
    # done: a second judge skips it
    main(["judge", "--run", str(run.root), "--json"])
    assert json.loads(capsys.readouterr().out)["skipped"] == 1
    # learn re-ran seed 1 (its result changed): judged again, seed 0's verdict kept
    write_model(run.skill_dir(task.id, 1) / "result.json", SkillResult(task_id=task.id, seed=1, success=False))
    main(["judge", "--run", str(run.root), "--json"])
    assert json.loads(capsys.readouterr().out)["done"] == 1
    assert load_verdict(run, task.id, 2) is None


@pytest.mark.slow
def test_the_settle_lets_go_of_the_cups_tracking_weld_so_a_tugged_arm_does_not_reset_the_scene(scenes):
    """An episode can end with the cup's tracking weld on and its target away from the cup (the arm
    limp, pulled by the weld); kept on while the referee settles with the robot's contacts off, it blew
    MuJoCo up, which reset the scene: a bag put in a bin was judged back where it started."""
    import mujoco

    from anomalygen.referee.settle import released_and_settled
    from anomalygen.robot.agent import Agent

    model, data, spec = load_scene(scenes["knife"])
    cabinet = next(o for o in spec.objects if o.asset.category == "StorageFurniture")
    top = max((c.name for c in cabinet.cavities if c.name.startswith("drawer")),
              key=lambda c: cavity_center(model, data, spec, cabinet.name, c)[2])
    put(model, data, KNIFE, cavity_center(model, data, spec, cabinet.name, top), size_z=0.02)
    track = model.equality(Agent.EE_TRACK).id
    data.eq_active[track] = 1
    data.mocap_pos[model.body(Agent.EE_TARGET).mocapid[0]] += [0.0, 0.0, 1.0]  # a target a metre off
    m, d, _, _ = released_and_settled(model, data, spec)
    assert d.eq_active[track] == 0 and data.eq_active[track] == 1  # let go on the copy only
    assert d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number == 0
    v = judge(scenes["knife"], model, data)
    assert v.resolved and _knife_verdict(v).detail == "fixed", v
