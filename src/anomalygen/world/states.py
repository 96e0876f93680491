"""Instance states: the words, how the builder shows them, and what the scene graph reports.

Why a module of its own: the builder, the compose step and the scene graph must agree on the words
(making them true is the builder's alone: ``set_states.py``, which the robot's side may not import).
The builder records the states it creates and no joint carries (a basin it filled:
``contains_water``; a wet patch: ``wet``) in ``PlacedObject.states``, and draws them (the water in the
basin, the glow of a burner that is on). The scene graph reports those plus what the simulation
says now, so a fix shows at once: ``on`` while any on/off control (a switch part in ``schema.part_labels``) is away from off
(else ``off``), ``lit`` for a burner or candle that is on, ``running`` for an open tap, ``handle_out``
for a pan whose handle reaches past the edge of what it stands on, ``face_down`` for an iron lying on
its soleplate.

How a task asks for a state: the builder makes its hazard class's state preconditions true
(``has_state(object=$v, state=...)``, ``is_on(object=$v)``) on the objects bound to those variables;
``TaskProposal.articulations`` with part "knob|switch|tap" and initial state "on" work as before.
"""

from __future__ import annotations

import numpy as np

from anomalygen.schema import JointState, part_labels
from anomalygen.schema.part_labels import HANDLE_GEOM

ON, OFF, LIT, RUNNING = "on", "off", "lit", "running"
CONTAINS_WATER, WET = "contains_water", "wet"
HANDLE_OUT, FACE_DOWN = "handle_out", "face_down"
BUILT_STATES = (CONTAINS_WATER, WET)  # set by the builder; every other state is read from joints and poses
SWITCHED_STATES = (ON, LIT)  # asking for one of these turns a control on
POSE_STATES = (HANDLE_OUT, FACE_DOWN)  # built by how the object is placed
KNOWN_STATES = (*SWITCHED_STATES, *BUILT_STATES, *POSE_STATES)

HOLDS_WATER = frozenset({"Sink", "Bathtub"})  # their asset has a hidden ``water`` geom in the basin
ALWAYS_WET = frozenset({"Puddle"})
LIT_WHEN_ON = frozenset({"Stove", "candle"})  # an open flame or a glowing burner when on
FACE_DOWN_CATEGORIES = frozenset({"iron"})
WATER_GEOM = "water"
GLOW_SUFFIX = "_glow"  # a geom "<control body>_glow" shows while that control is on
WATER_ALPHA = 0.55
GLOW_ALPHA = 0.95
UPRIGHT_COS = 0.7  # cos of the most an object's up axis may lean and still count as upright (45 deg)


def control_is_on(values: dict[str, float], joint) -> bool:
    """Whether a control joint stands away from its off value in ``values`` (joint name -> value)."""
    return abs(values.get(joint.name, joint.closed_value) - joint.closed_value) > 1e-9


def add_state(states: list[str], state: str) -> None:
    """Append ``state`` once: a state list never names one state twice."""
    if state not in states:
        states.append(state)


# ---------------------------------------------------------------------------- how the builder shows them


def handle_tip_x(asset) -> float | None:
    """Local x of the free end of the asset's long handle (None when it has none: a pot with two side
    grips), the geom a pan's "handle_out" is built and read from."""
    for geom in geoms_below(asset.spec.worldbody):
        if geom.name == HANDLE_GEOM:
            return float(geom.pos[0] + geom.size[0])
    return None


def why_cannot_show(asset, state: str) -> str | None:
    """Why this variant of a category that can show ``state`` cannot (a pot with two side grips has no
    handle to stick out; a sink model without the hidden water geom), None when it can. A category
    that never can is refused by ``set_states`` with what can; states read from controls (on, lit,
    running) are the part check's."""
    if state == HANDLE_OUT and handle_tip_x(asset) is None:
        return "has no long handle to stick out"
    if state == CONTAINS_WATER and asset.category in HOLDS_WATER \
            and not any(g.name == WATER_GEOM for g in geoms_below(asset.spec.worldbody)):
        return "has no basin to fill with water"
    return None


def show_states(root, placed) -> None:
    """Draw a placed object's states on its attached body (``compose.py``): water in a filled basin,
    the glow of each control that starts on. The asset hides both (alpha 0)."""
    on_bodies = {j.body for j in placed.asset.joints if control_is_on(placed.joint_values, j)}
    prefix = f"{placed.name}/"
    for geom in geoms_below(root):
        name = geom.name.removeprefix(prefix)
        if name == WATER_GEOM and CONTAINS_WATER in placed.states:
            geom.rgba = [*geom.rgba[:3], WATER_ALPHA]
        elif name.endswith(GLOW_SUFFIX) and name.removesuffix(GLOW_SUFFIX) in on_bodies:
            geom.rgba = [*geom.rgba[:3], GLOW_ALPHA]


def refresh_glows(model, data, spec) -> None:
    """Show each glow while its control is on and hide it when off, from the live joint values
    (for renders and videos of a scene whose controls the robot turns)."""
    import mujoco

    for obj in spec.objects:
        for js in obj.joint_states:
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, js.name)
            gid = _named_geom(model, f"{model.body(int(model.jnt_bodyid[jid])).name}{GLOW_SUFFIX}") if jid >= 0 else -1
            if gid >= 0:
                on = not js.is_closed(value=float(data.qpos[model.jnt_qposadr[jid]]))
                model.geom_rgba[gid, 3] = GLOW_ALPHA if on else 0.0


def geoms_below(body) -> list:
    """Every geom of an MjSpec body and its descendants."""
    out = list(body.geoms)
    for child in body.bodies:
        out.extend(geoms_below(child))
    return out


def _named_geom(model, name: str) -> int:
    import mujoco

    return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)


# ---------------------------------------------------------------------------- what the graph reports


def object_states(model, data, obj, joints: list[JointState], support_box=None) -> list[str]:
    """The perceived states of one object (``world/graph.py``): the builder's recorded states, the
    on/off reading of its controls, and the pose-based ones. ``support_box`` is the world (lo, hi)
    of the surface geom it rests on, if any."""
    out = list(obj.states)
    controls = [j for j in joints if part_labels.is_switch(j.label)]
    if controls:
        on = [j for j in controls if not j.is_closed()]
        add_state(out, ON if on else OFF)
        if on and obj.asset.category in LIT_WHEN_ON:
            add_state(out, LIT)
        if any(part_labels.canonical(j.label) == part_labels.TAP for j in on):
            add_state(out, RUNNING)
    body = model.body(obj.name)
    if obj.asset.category in FACE_DOWN_CATEGORIES and data.xmat[body.id][8] > UPRIGHT_COS:
        add_state(out, FACE_DOWN)  # its local up (the side away from the soleplate) points up
    if support_box is not None and _handle_beyond(model, data, obj.name, support_box):
        add_state(out, HANDLE_OUT)
    return out


def _handle_beyond(model, data, name: str, support_box) -> bool:
    """Does the object's handle geom reach past the edge of the surface box it rests on (x/y)?"""
    gid = _named_geom(model, f"{name}/{HANDLE_GEOM}")
    if gid < 0:
        return False
    tip = _far_end(model, data, gid)
    lo, hi = support_box
    return bool(np.any(tip[:2] < lo[:2]) or np.any(tip[:2] > hi[:2]))


def _far_end(model, data, gid: int) -> np.ndarray:
    """The end of a box-shaped handle farthest from its object's centre (its free end)."""
    centre = data.geom_xpos[gid]
    rot = data.geom_xmat[gid].reshape(3, 3)
    half = model.geom_size[gid]
    axis = int(np.argmax(half))
    ends = [centre + s * half[axis] * rot[:, axis] for s in (-1.0, 1.0)]
    body = model.geom_bodyid[gid]
    return max(ends, key=lambda p: float(np.linalg.norm(p[:2] - data.xipos[body][:2])))
