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
