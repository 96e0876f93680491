"""A floor safe behind a hinged door, built by the scene stage (real simulator): the door the access
step opens stays open once the arm lets go, and the compartment's depth is measured to its back
wall, not to the carcass's outside."""

from __future__ import annotations

import numpy as np
import pytest

from support.kb_scenes import build_with_kb_plans, kb_task

TASKS = {"spray": kb_task("t-spray-safe", "manage_chemical_risks", "Bottle", "cleaning_spray", "counter_edge",
                          container="Safe")}


@pytest.fixture(scope="module")
def opened(tmp_path_factory):
    from anomalygen.schema import DOOR
    from anomalygen.skills.episode import Episode
    from anomalygen.skills.scripted.access import open_for_access
    from anomalygen.world.graph import load_scene

    scene_dir, spec, _ = build_with_kb_plans(TASKS, tmp_path_factory.mktemp("safe_scene"), clutter=1)["spray"]
    m, d, spec = load_scene(scene_dir)
    ep = Episode(m, d, spec, rng=np.random.default_rng(0))
    res = open_for_access(ep, "safe_0", [DOOR])
    return ep, res


def _door(ep) -> float:
    return float(ep.driver.data.joint("safe_0/door_hinge").qpos[0])


@pytest.mark.slow
def test_the_opened_safe_door_stays_open_after_the_arm_lets_go(opened):
    """The drive leads the door with the arm's target ahead of the cup; let go under that strain a
    safe door sprang back shut. Opened, it must stay where it was left."""
    ep, res = opened
    assert res.success, res.detail
    q = _door(ep)
    lo, hi = ep.driver.model.joint("safe_0/door_hinge").range
    assert abs(q) > 0.5 * max(abs(lo), abs(hi))  # over half open
    ep.driver.settle(100)
    assert abs(_door(ep) - q) < 0.05


@pytest.mark.slow
def test_slackening_puts_the_arms_target_on_the_cup(opened):
    from anomalygen.skills.scripted.parts import _slacken

    ep, _ = opened
    drv = ep.driver
    drv.data.mocap_pos[drv._mocap] += np.array([0.05, 0.0, 0.0])  # a target left ahead of the cup
    _slacken(ep)
    assert np.linalg.norm(drv.data.mocap_pos[drv._mocap] - drv.data.xpos[drv.agent.cup]) < 1e-3


@pytest.mark.slow
def test_depth_inside_reaches_the_back_wall_not_the_carcass_outside(opened):
    """The measured compartment box runs to the carcass's outside; the depth an object can go in is
    that less the back wall (the geom across the compartment's far end)."""
    import mujoco

    from anomalygen.skills.scripted.laydown import depth_inside

    ep, _ = opened
    drv = ep.driver
    m, d = drv.model, drv.data
    lo, hi, out = ep.memory.compartments["safe_0"]
    k = int(np.argmax(np.abs(out[:2])))
    back = hi[k] if out[k] < 0 else lo[k]  # the carcass's far face
    root = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "safe_0/root")
    walls = [g for g in range(m.ngeom) if m.geom_bodyid[g] == root]
    # the back wall: the geom whose far face is the carcass's far face and that is thin along k
    thick = min(2 * float(np.abs(d.geom_xmat[g].reshape(3, 3) @ m.geom_size[g])[k]) for g in walls
                if abs(d.geom_xpos[g][k] - back) < 0.05)
    want = abs(hi[k] - lo[k]) - thick
    assert depth_inside(ep, lo, hi, out, "cleaning_spray_0") == pytest.approx(want, abs=0.01)
