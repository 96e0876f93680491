"""Switching off a latched push button on a scene the builder made, with the real simulator: it is
pulled out to off and stays off."""

from __future__ import annotations

from pathlib import Path

import pytest

BUTTON = "coffeemachine_0/power_button_press"


@pytest.mark.slow
def test_a_latched_coffee_machine_button_is_pulled_out_to_off_and_stays_off(tmp_path):
    """The seed-0 loop's t0055 at 4726c82, built verbatim: a coffee machine left on, its top power
    button latched pressed in (4.6 mm travel). The lead pulled it 10 mm past its stop and, let go, it
    sprang back in; led just to off, bringing the arm onto it before letting go pressed it 1.5 mm back;
    and left off, it crept back in under its own weight (MuJoCo's friction is soft) and was on again
    50 steps later."""
    from anomalygen.skills.scripted.controls import switch_off_control
    from support.built_task import episode_on_built_task

    ep = episode_on_built_task(Path(__file__).parent / "fixtures" / "coffee_machine_on.json", tmp_path / "scene")
    m, d = ep.driver.model, ep.driver.data
    jid = m.joint(BUTTON).id
    far = float(m.jnt_range[jid][1])
    assert float(d.joint(BUTTON).qpos[0]) > 0.8 * far  # built on: pressed in
    res = switch_off_control(ep, BUTTON, 0.0, far)
    assert res.success, res.detail
    ep.settle(200)
    assert abs(float(d.joint(BUTTON).qpos[0])) < 0.05 * far
    assert "off" in ep.graph().get("coffeemachine_0").states


@pytest.mark.slow
def test_a_latched_button_holds_where_it_is_set_either_way(tmp_path):
    """The builder latches a button set 'on': no return spring, and its weight compensated, so set off
    by hand it stays off, as set on it stays on."""
    import mujoco

    from support.built_task import episode_on_built_task

    ep = episode_on_built_task(Path(__file__).parent / "fixtures" / "coffee_machine_on.json", tmp_path / "scene")
    m, d = ep.driver.model, ep.driver.data
    jid = m.joint(BUTTON).id
    assert m.jnt_stiffness[jid] == 0.0 and m.body_gravcomp[m.jnt_bodyid[jid]] == 1.0
    on = float(d.joint(BUTTON).qpos[0])
    ep.settle(200)
    assert abs(float(d.joint(BUTTON).qpos[0]) - on) < 2e-4
    d.qpos[m.jnt_qposadr[jid]] = 0.0
    mujoco.mj_forward(m, d)
    ep.settle(200)
    assert abs(float(d.joint(BUTTON).qpos[0])) < 2e-4


@pytest.mark.slow
def test_a_lever_tap_set_running_stays_running_until_turned(tmp_path):
    """A single-lever tap the builder set running keeps its opening: its weight is compensated, as a
    real tap cartridge holds any position. Held by friction alone, MuJoCo's soft friction let the
    bathtub's lever creep shut in about 4 s (the seed-0 task t0084), so a robot that did nothing was
    judged to have turned the tap off."""
    from anomalygen.world.states import RUNNING
    from support.built_task import episode_on_built_task

    ep = episode_on_built_task(Path(__file__).parent / "fixtures" / "bathtub_tap_running.json", tmp_path / "scene")
    m, d = ep.driver.model, ep.driver.data
    lever = "bathtub_0/lever_hinge"
    jid = m.joint(lever).id
    assert m.body_gravcomp[m.jnt_bodyid[jid]] == 1.0
    opened = float(d.joint(lever).qpos[0])
    assert opened < -0.3  # about 90 % of its 0.6 rad lift: running
    ep.settle(1000)  # 2 s of nothing
    assert abs(float(d.joint(lever).qpos[0]) - opened) < 1e-3
    assert RUNNING in ep.graph().get("bathtub_0").states
