"""Making a task's instance states true in the scene being built (the builder's side of ``states.py``).

Why apart from ``states.py``: the scene graph reads states and is shared with the robot's side; how a
state is set up reads the selection and the catalogue, which the robot's side may not import.
"""

from __future__ import annotations

import math

import numpy as np

from anomalygen.scene.layout import DROP_GAP
from anomalygen.schema import part_labels
from anomalygen.world.states import (
    ALWAYS_WET,
    BUILT_STATES,
    CONTAINS_WATER,
    FACE_DOWN,
    FACE_DOWN_CATEGORIES,
    HANDLE_OUT,
    HOLDS_WATER,
    KNOWN_STATES,
    ON,
    SWITCHED_STATES,
    WET,
    add_state,
    control_is_on,
    handle_tip_x,
)

BURNER, BURNER_CONTROL = "burner_", "knob_"  # surface "burner_k" is heated by the control body "knob_k"
HANDLE_OVERHANG = (0.04, 0.08)  # m the handle's tip reaches past the edge for "handle_out"
TRIES = 30



def wanted_states(sel) -> list[tuple[object, str]]:
    """(chosen object, state word) pairs the task asks for: its class's non-negated ``has_state`` /
    ``is_on`` preconditions on the role variables, and ``scenario.states`` by catalogue name."""
    from anomalygen.errors import ItemFailed
    from anomalygen.scene.asset_choice import resolve_name

    out = []
    by_var = {"$hazard": sel.hazard_var or sel.hazard, "$target": sel.target, "$container": sel.container,
              "$support": sel.support_var}
    for call in sel.hc.preconditions if sel.hc is not None else []:
        if not call.negate and call.name in ("has_state", "is_on"):
            ch = by_var.get(str(call.args.get("object", "")))
            if ch is not None:
                out.append((ch, ON if call.name == "is_on" else str(call.args.get("state", ""))))
    for name, words in sel.task.scenario.states.items():
        ch = sel.by_catalogue.get(resolve_name(name))
        if ch is None:
            raise ItemFailed(f"the task asks for {name} to be {', '.join(words)}, but the scene holds no {name}")
        out += [(ch, w) for w in words]
    for ch, state in out:
        if state not in KNOWN_STATES:
            raise ItemFailed(f"no way to build the state {state!r} of {ch.catalogue}; known: {', '.join(KNOWN_STATES)}")
    return out


def set_initial_states(sel) -> None:
    """Make the asked-for states true on the chosen objects (``scene/casting.py``), before placement.

    A water state goes to a basin that can hold water; "on"/"lit" turns one on/off control on (one
    burner of a stove; ``arrange_states`` may move it under what was put on the stove) unless one
    already is, and is recorded as a state of an object with no control (a lit cigarette). A
    hazard-free build leaves every control off but keeps the water: a full sink alone is no hazard.
    Negated preconditions need nothing: off and dry are how things are built.
    """
    from anomalygen.errors import ItemFailed

    for ch in sel.by_catalogue.values():
        if ch.catalogue in ALWAYS_WET:
            add_state(ch.states, WET)
    for ch, state in wanted_states(sel):
        if state in SWITCHED_STATES:
            controls = switch_joints(ch.asset)
            if sel.hazard_free:
                continue
            if not controls:
                add_state(ch.states, state)
            elif not any(control_is_on(ch.joint_values, j) for j in controls):
                from anomalygen.scene.asset_choice import open_value

                joint = controls[int(sel.rng.integers(len(controls)))]
                ch.joint_values[joint.name] = open_value(joint, "on", sel.rng)
        elif state in BUILT_STATES:
            if state == CONTAINS_WATER and ch.catalogue not in HOLDS_WATER:
                raise ItemFailed(f"{ch.catalogue} cannot hold water; what can: {', '.join(sorted(HOLDS_WATER))}")
            add_state(ch.states, state)
        elif state == FACE_DOWN and ch.catalogue not in FACE_DOWN_CATEGORIES:
            raise ItemFailed(f"face_down is an iron lying on its soleplate; {ch.catalogue} is not an iron")


def arrange_states(sel, lay, placed: dict) -> None:
    """After placement (``scene/build.py``): the burner that is on is the one under what stands on
    the stove, and a pan asked to have its handle out is turned so that the handle reaches past the
    edge of its surface that faces the room (where the robot stands)."""
    for ch, state in wanted_states(sel):
        if state == HANDLE_OUT and not sel.hazard_free and ch.name in placed:
            _turn_handle_out(lay, placed[ch.name], placed)
    for holder in placed.values():
        if holder.asset is not None and any(s.name.startswith(BURNER) for s in holder.asset.surfaces):
            _light_burner_under(holder, placed)


def _light_burner_under(holder, placed: dict) -> None:
    """Move the 'on' of a burner knob to the burner nearest the (first) thing standing on the stove."""
    from anomalygen.scene.layout import surface_world

    knobs = {j.body: j for j in holder.asset.joints}
    on = [j for j in knobs.values() if control_is_on(holder.joint_values, j)]
    items = sorted((p for p in placed.values() if p.support.split(":")[0] == holder.name),
                   key=lambda p: p.role.value != "hazard")
    if not on or not items:
        return
    where = items[0].world_center()[:2]
    burners = [s for s in holder.asset.surfaces if s.name.startswith(BURNER)]
    near = min(burners, key=lambda s: float(np.linalg.norm(
        (lambda w: (w[0] + w[1]) / 2)(surface_world(holder, s.center, s.half_size)) - where)))
    joint = knobs.get(near.name.replace(BURNER, BURNER_CONTROL, 1))
    if joint is None or control_is_on(holder.joint_values, joint):
        return
    holder.joint_values[joint.name] = holder.joint_values.pop(on[0].name)


def _turn_handle_out(lay, p, placed: dict) -> None:
    """Turn a pan on its surface so its handle (local +x, the catalogue's convention) points out over
    the room-facing edge, the tip ``HANDLE_OVERHANG`` beyond it, its body still on the surface."""
    from anomalygen.errors import ItemFailed
    from anomalygen.scene.instances import surface_of

    tip = handle_tip_x(p.asset)
    holder = placed.get(p.support.split(":")[0])
    if tip is None:
        raise ItemFailed(f"{p.catalogue} has no long handle to stick out")
    if holder is None or p.inside:
        raise ItemFailed(f"a handle sticks out over an edge only on a surface; {p.name} is on the {p.support}")
    lo_xy, hi_xy, top = surface = surface_of(holder)
    axis, sign = lay.robot_edge(surface)
    other = 1 - axis
    bound = hi_xy[axis] if sign > 0 else lo_xy[axis]
    yaw0, pos0 = p.yaw, p.pos.copy()
    p.yaw = (0.0 if sign > 0 else math.pi) if axis == 0 else (math.pi / 2 if sign > 0 else -math.pi / 2)
    half = p.world_half()
    for _ in range(TRIES):
        pos = np.zeros(3)
        pos[axis] = bound + sign * lay.rng.uniform(*HANDLE_OVERHANG) - sign * tip
        room = (hi_xy[other] - lo_xy[other]) / 2 - half[other]
        pos[other] = (lo_xy[other] + hi_xy[other]) / 2 + lay.rng.uniform(-1, 1) * max(room, 0.0)
        pos[2] = top - p.lo[2] + DROP_GAP
        p.pos = pos
        if not lay.collides(p, ignore=(holder.name,)):
            return
    p.yaw, p.pos = yaw0, pos0
    raise ItemFailed(f"no room to turn {p.name}'s handle out over {holder.name}'s edge")


def switch_joints(asset) -> list:
    """The asset's on/off controls (knobs, switches, taps; a button is a switch)."""
    return [j for j in asset.joints if part_labels.is_switch(j.label)]
