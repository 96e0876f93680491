"""Switching a control off by script: hold the knob, switch or snuffer by suction and lead it to off.

The learned switch-off skill (:mod:`~anomalygen.skills.learned.part_subtask`) and this primitive run
the family's one sequence (:func:`~anomalygen.skills.part_motion.hold_and_lead`): its grasp (the cup
on the part's face, off the axis for a knob, on top for a push switch), its observation
(``PartReadout``), its control loop (``lead_held_part``) and letting go; here the actions come from
the family's scripted reference (``reference_action``) instead of a policy, and a hold that slips is
tried again. It is what a ``push`` or ``switch_off`` step on a control runs, so also what a failed SAC
switch-off falls back to: the panel grasp of :mod:`~anomalygen.skills.scripted.parts` (doors, lids)
holds a knob by its rim, where leading it round drags a light appliance off its table.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from anomalygen.schema import part_labels
from anomalygen.skills.part_motion import (
    POS_SCALE,
    REFERENCE_MOVE,
    PartReadout,
    hold_and_lead,
    reference_action,
)
from anomalygen.skills.registry import SkillOutcome

if TYPE_CHECKING:  # pragma: no cover
    from anomalygen.skills.episode import Episode

CONTROL_LABELS = (part_labels.KNOB, part_labels.SWITCH, part_labels.BUTTON, part_labels.DIAL)  # turned or pressed to off here
OFF_TOL = 0.01  # fraction of the travel from off at which the script lets go (the graph's "off" is 5 %)
HORIZON = 90  # control steps per hold (the reference turns a knob from 90 % on to off in 15-26)
ATTEMPTS = 2  # holds tried before giving up (a hold can slip off a small knob)
TURN_PER_STEP = 0.2  # rad a held knob is led round per control step at most


def paced(readout):
    """The family's scripted reference, its move along the part's path cut to what is left of the
    travel: a 6 mm push switch led at the reference's 18 mm a step is driven through its end stop and
    springs back when let go; a knob's last few degrees are approached as gently. A knob is turned at
    most ``TURN_PER_STEP`` a step: the reference's 18 mm along the tangent of a dial held 1 cm off its
    axis is more than a radian, the cup runs off the dial's circle and the weld hauls the appliance
    after it (a 3 kg fan heater tipped over)."""
    from anomalygen.robot.agent import Agent

    def act(obs: np.ndarray) -> np.ndarray:
        lever = float(np.linalg.norm(obs[6:9])) / POS_SCALE if readout.hinge else 1.0
        left = abs(float(obs[9])) * readout.span * lever  # m the held point still has to go
        turn = TURN_PER_STEP * lever if readout.hinge else REFERENCE_MOVE * Agent.STEP_POS  # m a step
        return reference_action(obs, min(REFERENCE_MOVE, left / Agent.STEP_POS, turn / Agent.STEP_POS))

    return act


def switch_off_control(ep: Episode, joint: str, closed: float, far: float) -> SkillOutcome:
    """Hold the control ``joint`` (off at ``closed``, fully on at ``far``) and lead it to off."""
    drv = ep.driver
    s0 = drv.steps
    readout = PartReadout(drv.model, joint, closed, far)
    if abs(readout.fraction(drv.data)) <= OFF_TOL:
        return SkillOutcome(True, 0, f"{joint} already off ({drv.data.joint(joint).qpos[0]:.3f})")
    notes = []
    for attempt in range(1, ATTEMPTS + 1):
        lead = hold_and_lead(ep, readout, lambda: paced(readout), horizon=HORIZON, tol=OFF_TOL)
        if not lead.held:
            notes.append(f"hold {attempt}: {lead.why}")
            continue
        notes.append(f"hold {attempt}: led {'to off' if lead.off else 'towards off'} in {lead.steps} steps"
                     + (f" ({lead.stopped})" if lead.stopped else ""))
        if readout.at_off(drv.data):
            break
    q = float(drv.data.joint(joint).qpos[0])
    ok = readout.at_off(drv.data)
    return SkillOutcome(ok, drv.steps - s0, f"{joint} = {q:.3f} (off {closed:.3f}, on {far:.3f}); {'; '.join(notes)}")
