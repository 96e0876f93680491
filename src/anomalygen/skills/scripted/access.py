"""Container access: open a container so an object can go in (or come out) and shut it again.

Which part to open is a choice made from the live scene: every lid and flap; else the highest
drawer within reach; else the door of the highest reachable compartment (measured with the door
shut, recorded in the episode's ``memory.compartments`` for the place and take-out steps); with ``contents``, the door
or drawer in front of that object. The parts are driven by :func:`parts.actuate_part`.
"""

from __future__ import annotations

import numpy as np

from anomalygen.schema import DOOR, DRAWER, ENCLOSING_LABELS, LID_LABELS
from anomalygen.skills.episode import Episode
from anomalygen.skills.geometry import HINGE, static_box
from anomalygen.skills.registry import SkillOutcome
from anomalygen.skills.scripted.parts import _world, actuate_part, grasp_candidates

LIDS = LID_LABELS
OPEN_FRACTION = 0.85  # how far a lid, flap or drawer is opened to put something in


def closure_joints(ep: Episode, obj: str, labels) -> list:
    """The object's JointStates whose label is one of ``labels``."""
    return [js for o in ep.spec.objects if o.name == obj for js in o.joint_states if js.label in labels]


def _far(js) -> float:
    lo, hi = js.range
    return hi if abs(hi - js.closed_value) >= abs(lo - js.closed_value) else lo


def best_drawer(ep: Episode, obj: str, drawers: list):
    """The drawer to put things in: the highest one whose top is within the arm's comfortable band."""
    drv = ep.driver
    def top(js) -> float:
        return float(drv.aabb(drv.joint_body(js.name))[1][2])

    ok = [js for js in drawers if 0.2 < top(js) < 1.15]
    return max(ok or drawers, key=top) if (ok or drawers) else None


def compartment_behind(ep: Episode, obj: str, js) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lo, hi, outward normal) of the space behind a shut door: the door's face extent, as deep as
    the carcass reaches behind it.

    A hinged door's handle is pulled outwards, so its grasp normal says which way the door faces; a
    sliding door's handle is pulled sideways, so its face is its panel's thinnest side, on the side
    of the carcass the panel stands (a sideways normal measured a compartment of no depth)."""
    drv = ep.driver
    dlo, dhi = drv.aabb(drv.joint_body(js.name))
    clo, chi = static_box(ep, obj)
    if js.type == "slide":
        k = int(np.argmin((dhi - dlo)[:2]))
        n = np.zeros(3)
        n[k] = 1.0 if (dlo[k] + dhi[k]) > (clo[k] + chi[k]) else -1.0
    else:
        n = _world(ep, grasp_candidates(ep, js.name, js.closed_value)[0])[1]
        k = int(np.argmax(np.abs(n[:2])))
    lo, hi = dlo.copy(), dhi.copy()
    if n[k] < 0:  # the door faces -k: the compartment runs towards +k
        lo[k], hi[k] = dhi[k], chi[k]
    else:
        lo[k], hi[k] = clo[k], dlo[k]
    out = np.zeros(3)
    out[k] = np.sign(n[k])
    return lo, hi, out


def best_door(ep: Episode, obj: str, doors: list):
    """The door whose compartment is tall enough for the hand (0.18 m) and the highest within reach."""
    drv = ep.driver
    ok = []
    for js in doors:
        if abs(float(drv.data.joint(js.name).qpos[0]) - js.closed_value) > 0.1:
            continue  # only shut doors have a known compartment behind them
        lo, hi, _ = compartment_behind(ep, obj, js)
        if hi[2] - lo[2] >= 0.18 and lo[2] < 1.0:  # low doors too: the object then goes in sideways
            ok.append((float(lo[2]), js))
    return max(ok, key=lambda t: t[0])[1] if ok else None


def _compartment_when_shut(ep: Episode, obj: str, js):
    """``compartment_behind`` of a door in whatever state it is: measured with the door put shut for
    the kinematics only (the state is restored, no time passes)."""
    import mujoco

    drv = ep.driver
    adr = drv.model.jnt_qposadr[drv.model.joint(js.name).id]
    q = float(drv.data.qpos[adr])
    drv.data.qpos[adr] = js.closed_value
    mujoco.mj_kinematics(drv.model, drv.data)
    try:
        return compartment_behind(ep, obj, js)
    finally:
        drv.data.qpos[adr] = q
        mujoco.mj_forward(drv.model, drv.data)


def holding_closure(ep: Episode, obj: str, contents: str):
    """The door or drawer of ``obj`` in front of ``contents``, open or shut: (JointState, compartment
    or None). A fridge has a freezer drawer or door and a main door; the one to open, and the way the
    cup comes in, is the one whose compartment holds the object's centre."""
    drv = ep.driver
    lo_c, hi_c = drv.aabb(contents)
    c = (lo_c + hi_c) / 2
    for js in closure_joints(ep, obj, [DOOR]):
        lo, hi, out = _compartment_when_shut(ep, obj, js)
        if np.all(c >= lo - 0.03) and np.all(c <= hi + 0.03):
            return js, (lo, hi, out)
    for js in closure_joints(ep, obj, [DRAWER]):
        lo, hi = drv.aabb(drv.joint_body(js.name))
        if np.all(c[:2] >= lo[:2]) and np.all(c[:2] <= hi[:2]) and lo[2] <= c[2] <= hi[2] + 0.05:
            return js, None
    return None


def _record_compartment(ep: Episode, obj: str, room) -> None:
    """Remember the compartment the place and take-out steps go through, and where its container
    stood then (a light container that slides carries its compartment along)."""
    drv = ep.driver
    ep.memory.compartments[obj] = room
    ep.memory.compartment_anchor[obj] = drv.data.xpos[drv.body_id(obj)].copy()


def open_for_access(ep: Episode, obj: str, labels, contents: str | None = None):
    """Open the container so an object can go in: every lid and flap, or the best drawer; with
    ``contents`` (an object to take out), the door or drawer in front of that object.

    Records what was opened in ``ep.memory.opened[obj]`` (so the place step drops into an opened drawer
    and the close step shuts exactly these) and returns a SkillOutcome.
    """
    drv = ep.driver

    s0 = drv.steps
    if contents is not None and obj in ep.memory.opened:  # a second attempt: the same part again
        chosen = [js for js in closure_joints(ep, obj, CLOSURES_ALL) if js.name in ep.memory.opened[obj]]
    elif contents is not None:
        found = holding_closure(ep, obj, contents)
        if found is None:
            return SkillOutcome(True, 0, f"{contents} lies behind no door or drawer of {obj}: nothing to open")
        js, room = found
        if room is not None:
            _record_compartment(ep, obj, room)
        chosen = [js]
    else:
        chosen = closure_joints(ep, obj, [lab for lab in labels if lab in LIDS])
    if not chosen:
        drawer = best_drawer(ep, obj, closure_joints(ep, obj, [DRAWER]))
        chosen = [drawer] if drawer is not None else []
    if not chosen and obj in ep.memory.compartments:
        # a second attempt on a door left part open: the door and its compartment were chosen and
        # measured (shut) the first time; now it is open, best_door would not know it any more
        chosen = [js for js in closure_joints(ep, obj, [DOOR]) if js.name in ep.memory.opened.get(obj, [])]
    if not chosen:
        door = best_door(ep, obj, closure_joints(ep, obj, [DOOR]))
        if door is None:
            return SkillOutcome(False, 0, f"{obj} has no lid, flap, drawer or door with a reachable "
                                             "compartment behind it")
        _record_compartment(ep, obj, compartment_behind(ep, obj, door))
        chosen = [door]
    ep.memory.opened[obj] = [js.name for js in chosen]
    ok, details = True, []
    for js in chosen:
        goal = js.closed_value + OPEN_FRACTION * (_far(js) - js.closed_value)
        tol = 0.3 * abs(js.range[1] - js.range[0])  # over half open is open enough to put things in
        q = float(drv.data.joint(js.name).qpos[0])
        if abs(q - js.closed_value) < abs(goal - js.closed_value) - tol:
            r = actuate_part(ep, js.name, goal, closed=js.closed_value, tol=tol)
            ok &= r.success
            details.append(r.detail)
        steep = _near_upright(ep, js)
        sgn = np.sign(_far(js) - js.closed_value)
        if ok and steep is not None and (steep - float(drv.data.joint(js.name).qpos[0])) * sgn > 0.1:
            # A lid is held where it is left (hinge friction), and one left half open leans over the
            # opening: a carton lowered in hits it. Lift it on to just short of upright, but give up
            # as soon as the container itself moves (near upright the cup pulls sideways, and a light
            # box slides rather than its stiff lid turning); what it reached is kept.
            before = float(drv.data.joint(js.name).qpos[0])
            r = actuate_part(ep, js.name, steep, closed=js.closed_value, tol=0.03, attempts=2,
                             max_drag=STEEP_MAX_DRAG)
            details.append("lifted on: " + r.detail)
            if (before - float(drv.data.joint(js.name).qpos[0])) * sgn > 0.1:  # knocked back down on the way
                r = actuate_part(ep, js.name, goal, closed=js.closed_value, tol=tol)
                ok &= r.success
                details.append("again: " + r.detail)
    return SkillOutcome(ok, drv.steps - s0, "opened: " + "; ".join(details) if details else f"{obj} already open")


PAST_UPRIGHT = 0.1  # rad: how far past upright a lid is lifted on to (or to its stop)
STEEP_MAX_DRAG = 0.03  # m the container may move while its lid is lifted on


def _upright_value(ep: Episode, joint: str) -> float | None:
    """Joint value at which a hinged part's centre of mass stands straight above its (horizontal)
    hinge axis; None for a slide or a hinge that is not horizontal."""
    drv = ep.driver
    m, d = drv.model, drv.data
    j = m.joint(joint).id
    if m.jnt_type[j] != HINGE:
        return None
    axis = d.xaxis[j] / np.linalg.norm(d.xaxis[j])
    if abs(axis[2]) > 0.3:
        return None
    up = np.array([0.0, 0.0, 1.0]) - axis * axis[2]
    r = d.xipos[int(m.jnt_bodyid[j])] - d.xanchor[j]
    r = r - axis * np.dot(r, axis)
    if np.linalg.norm(r) < 1e-4:
        return None
    up, r = up / np.linalg.norm(up), r / np.linalg.norm(r)
    phi = float(np.arctan2(np.dot(axis, np.cross(r, up)), np.dot(r, up)))  # the turn taking r to up
    return float(d.qpos[m.jnt_qposadr[j]]) + phi


def _near_upright(ep: Episode, js) -> float | None:
    """The value just short of upright for a hinged lid or flap (its own stop if that comes first),
    None for other parts."""
    if js.label not in LIDS:
        return None
    upright = _upright_value(ep, js.name)
    if upright is None:
        return None
    far = _far(js)
    sgn = np.sign(far - js.closed_value)
    if (upright - js.closed_value) * sgn <= 0:
        return None
    steep = upright + sgn * PAST_UPRIGHT
    return float(far - sgn * 0.02 if (steep - far) * sgn > -0.02 else steep)


def _falls_shut(ep: Episode, joint: str, closed: float) -> bool:
    """Would gravity swing this hinged part back towards closed? (its centre of mass is on the
    closed side of the vertical plane through the hinge axis)"""
    drv = ep.driver
    m, d = drv.model, drv.data
    j = m.joint(joint).id
    body = int(m.jnt_bodyid[j])
    axis = d.xaxis[j]
    q = float(d.qpos[m.jnt_qposadr[j]])
    torque = float(np.dot(np.cross(d.xipos[body] - d.xanchor[j], np.array([0.0, 0.0, -1.0])), axis))
    # gravity torque along the axis pushes q towards closed when its sign opposes the opening direction
    return bool(torque * np.sign(q - closed) < 0)


def close_opened(ep: Episode, obj: str, *, every: bool = False):
    """Shut the parts ``open_for_access`` opened on ``obj`` (hinged lids last-opened first); with
    ``every``, also the ones found open (a fridge the object came out of: every door it has)."""
    drv = ep.driver

    s0 = drv.steps
    names = list(reversed(ep.memory.opened.get(obj, [])))
    if every:
        names += [js.name for js in closure_joints(ep, obj, CLOSURES_ALL) if js.name not in names]
    ok, details = True, []
    for js in closure_joints(ep, obj, CLOSURES_ALL):
        if js.name not in names:
            continue
        tol = 0.025 * abs(js.range[1] - js.range[0])
        if abs(float(drv.data.joint(js.name).qpos[0]) - js.closed_value) <= tol:
            continue
        r = actuate_part(ep, js.name, js.closed_value, closed=js.closed_value, tol=tol)
        ok &= r.success
        details.append(r.detail)
    return SkillOutcome(ok, drv.steps - s0, "; ".join(details) or f"nothing of {obj} left open")


CLOSURES_ALL = ENCLOSING_LABELS
