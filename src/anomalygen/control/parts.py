"""Grasp-and-drive primitive for articulated parts: doors, lids, flaps and drawers.

Pushing a part (``primitives.push_part``) cannot open anything, cannot lift a fold-down oven door and
lets a light door bounce back open. Here the suction cup holds the part itself (the scene builder adds
a suction weld for every hinged or sliding body) and drags the grasped point along the arc (hinge) or
line (slide) the part allows, so the part goes exactly where it is led and stops there.

The grasp point lies on a face of the part's own box: the face that points out of the cabinet when
the part is closed (the front of a door or drawer, the top of a lid), 75 % of the way from the hinge
to the far edge. When that face is out of reach (an oven door folded down shows its front to the
floor, a toilet lid leaning on the tank shows it to the wall) the opposite face is used, and the drive
stops short of closed so the cup is not trapped; the next attempt takes the outer face. The weld
holds the position only (torque scale 0), so the part may turn under the cup while the arm keeps up.
Each attempt picks a base pose facing the middle of the remaining arc; an attempt ends when the part
stops following (out of reach, blocked), and the primitive re-grasps up to ``attempts`` times.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from anomalygen.control.driver import PRE_CONTACT, PrimitiveResult
from anomalygen.control.geometry import HINGE, SLIDE, static_box

INNER_FACE_STOP = 0.4  # rad: a grasp on the inner face lets go this far from closed
LEAD_HINGE = 0.06
MAX_DRAG = 0.10  # m the container may be dragged by its part before the drive gives up
MAX_TILT = 0.35  # rad it may tip
COMFORT_Z = 0.95  # m: height at which the arm holds a tall door


@dataclass
class PartGrasp:
    body: int
    point_local: np.ndarray  # grasp point, part body frame
    normal_local: np.ndarray  # outward normal of the grasped face, part body frame
    outer: bool  # the face that points out of the cabinet when closed
    beyond_local: np.ndarray | None = None  # just past the free edge (hinged parts), part body frame


def _rot(axis: np.ndarray, angle: float) -> np.ndarray:
    a = axis / (np.linalg.norm(axis) + 1e-12)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * (k @ k)


def part_transform(drv, joint: str, dq: float):
    """(R, t) moving a world point with the part when the joint value changes by ``dq``."""
    m, d = drv.model, drv.data
    j = m.joint(joint).id
    axis = d.xaxis[j].copy()
    if m.jnt_type[j] == SLIDE:
        return np.eye(3), axis / np.linalg.norm(axis) * dq
    r = _rot(axis, dq)
    anchor = d.xanchor[j]
    return r, anchor - r @ anchor


def _body_box(drv, body: int) -> tuple[np.ndarray, np.ndarray]:
    """Local AABB (body frame) of the body's own collision geoms (all geoms if none collide)."""
    import mujoco

    m = drv.model
    geoms = [g for g in range(m.ngeom) if m.geom_bodyid[g] == body]
    coll = [g for g in geoms if m.geom_contype[g] or m.geom_conaffinity[g]]
    los, his = [], []
    for g in coll or geoms:
        rg = np.zeros(9)
        mujoco.mju_quat2Mat(rg, m.geom_quat[g])
        rg = rg.reshape(3, 3)
        c, h = m.geom_aabb[g, :3], m.geom_aabb[g, 3:]
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h + c
        pts = corners @ rg.T + m.geom_pos[g]
        los.append(pts.min(axis=0))
        his.append(pts.max(axis=0))
    return np.min(los, axis=0), np.max(his, axis=0)


def _object_root(m, body: int) -> int:
    while m.body_parentid[body] != 0:
        body = int(m.body_parentid[body])
    return body


EDGE_FACE = 0.05  # m: a face narrower than this is an edge the cup cannot seal on


def grasp_candidates(drv, joint: str, closed: float) -> list[PartGrasp]:
    """The outer and the inner face of the part, with a grasp point each (outer first)."""
    m, d = drv.model, drv.data
    j = m.joint(joint).id
    body = int(m.jnt_bodyid[j])
    lo, hi = _body_box(drv, body)
    rb = d.xmat[body].reshape(3, 3)
    q = float(d.qpos[m.jnt_qposadr[j]])
    rc, tc = part_transform(drv, joint, closed - q)  # current -> closed pose
    clo, chi = static_box(drv, m.body(_object_root(m, body)).name)
    centre = (clo + chi) / 2  # the carcass: what no hinge or slide moves
    axis_w = d.xaxis[j] / np.linalg.norm(d.xaxis[j])
    axis_l = rb.T @ axis_w
    size = hi - lo
    panel = False
    if m.jnt_type[j] == SLIDE:
        k = int(np.argmax(np.abs(axis_l)))  # the face across the slide direction: the drawer front
        # A sliding sash (or a sliding door) moves in its own plane: the face across the slide is a
        # 3 cm edge, and a cup on that edge leaves the arm beside the pane, where backing off drags
        # the sash along and going home shoves it shut again. Such a panel is held by its broad face
        # from the room side and slid sideways.
        edge = sorted(size[i] for i in range(3) if i != k)
        thin = int(np.argmin(size))
        upright = abs(rb[2, thin]) < 0.3 and abs(axis_w[2]) < 0.3  # a standing pane sliding sideways
        if edge[0] < EDGE_FACE and thin != k and upright:
            k, panel = thin, True
    else:
        # thinnest box axis that is not the hinge axis: across the panel
        cands = [i for i in range(3) if abs(axis_l[i]) < 0.7]
        k = min(cands, key=lambda i: size[i])
    out: list[PartGrasp] = []
    for sgn in (1.0, -1.0):
        n_l = np.zeros(3)
        n_l[k] = sgn
        p_l = (lo + hi) / 2
        p_l[k] = hi[k] if sgn > 0 else lo[k]
        if m.jnt_type[j] == HINGE:
            # 75 % of the way from the axis to the far edge, along the panel's long in-plane direction
            anchor_l = rb.T @ (d.xanchor[j] - d.xpos[body])
            others = [i for i in range(3) if i != k]
            i_far = max(others, key=lambda i: abs(abs(axis_l[i]) - 1.0) * size[i])
            far = hi[i_far] if abs(hi[i_far] - anchor_l[i_far]) > abs(lo[i_far] - anchor_l[i_far]) else lo[i_far]
            p_l[i_far] = anchor_l[i_far] + 0.75 * (far - anchor_l[i_far])
            # along a vertical hinge, hold the door at a comfortable height (a freezer door's middle
            # is out of the arm's reach)
            i_ax = int(np.argmax(np.abs(axis_l)))
            if abs(axis_w[2]) > 0.7 and i_ax != k:
                z0 = float((d.xpos[body] + rb @ p_l)[2])
                want = float(np.clip(COMFORT_Z, z0 - (p_l[i_ax] - lo[i_ax]) * abs(axis_w[2]) + 0.06,
                                     z0 + (hi[i_ax] - p_l[i_ax]) * abs(axis_w[2]) - 0.06))
                p_l[i_ax] += (want - z0) / (rb[2, i_ax] if abs(rb[2, i_ax]) > 1e-6 else 1.0)
        beyond = None
        if m.jnt_type[j] == HINGE:  # 12 cm past the free edge, level with the grasp point
            beyond = p_l.copy()
            beyond[i_far] = far + 0.12 * np.sign(far - anchor_l[i_far])
        p_w = d.xpos[body] + rb @ p_l
        n_w = rb @ n_l
        p_c, n_c = rc @ p_w + tc, rc @ n_w
        if m.jnt_type[j] == SLIDE and not panel:  # a drawer's front faces the way it slides out
            lo_r, hi_r = m.jnt_range[j]
            far = hi_r if abs(hi_r - closed) >= abs(lo_r - closed) else lo_r
            outer = bool(np.dot(n_w, axis_w) * np.sign(far - closed) > 0)
        else:  # a door's or lid's outer face looks away from the carcass when shut
            outer = bool(np.dot(n_c, p_c - centre) > 0)
        out.append(PartGrasp(body, p_l, n_l, outer=outer, beyond_local=beyond))
    out.sort(key=lambda g: not g.outer)
    return out


def _world(drv, g: PartGrasp) -> tuple[np.ndarray, np.ndarray]:
    d = drv.data
    rb = d.xmat[g.body].reshape(3, 3)
    return d.xpos[g.body] + rb @ g.point_local, rb @ g.normal_local


def _on_surface(drv, g: PartGrasp) -> PartGrasp:
    """Move the grasp point onto the part's real surface along the face normal (a ray): the box of a
    door with a handle has its front face at the handle's tip, centimetres in front of the panel."""
    import mujoco

    from anomalygen.scene import robot

    m, d = drv.model, drv.data
    p, n = _world(drv, g)
    part = robot.subtree_geoms(m, g.body)
    start = p + n * 0.05
    geomid = np.zeros(1, dtype=np.int32)
    travelled = 0.0
    for _ in range(6):
        dist = mujoco.mj_ray(m, d, start, -n, None, 1, -1, geomid)
        if dist < 0 or travelled + dist > 0.25:
            return g
        hit = start - n * dist
        if part[int(geomid[0])]:
            rb = d.xmat[g.body].reshape(3, 3)
            return PartGrasp(g.body, rb.T @ (hit - d.xpos[g.body]), g.normal_local, g.outer, g.beyond_local)
        travelled += dist + 1e-4
        start = hit - n * 1e-4
    return g


def _accessible(n_w: np.ndarray) -> bool:
    """A face the cup can come at: not facing the floor."""
    return bool(n_w[2] > -0.5)


def actuate_part(drv, joint: str, goal: float, *, closed: float, tol: float = 0.02, attempts: int = 4,
                 max_steps: int = 900, max_drag: float = MAX_DRAG):
    """Hold the part by suction and lead it to ``goal``; re-grasp when it stops following."""
    from anomalygen.control.ik import quat_z_to
    from anomalygen.scene import robot

    m, d = drv.model, drv.data
    j = m.joint(joint).id
    adr = m.jnt_qposadr[j]
    hinge = m.jnt_type[j] == HINGE
    s0 = drv.steps
    name = m.body(int(m.jnt_bodyid[j])).name
    notes = []

    def q() -> float:
        return float(d.qpos[adr])

    for attempt in range(attempts):
        if abs(q() - goal) <= tol or drv.steps - s0 > max_steps:
            break
        grasps = [g for g in grasp_candidates(drv, joint, closed) if _accessible(_world(drv, g)[1])]
        if not grasps:
            notes.append("no reachable face")
            break
        g = _on_surface(drv, grasps[0])
        stop = goal
        if not g.outer and hinge and abs(goal - closed) < INNER_FACE_STOP:
            stop = closed + np.sign(q() - closed) * INNER_FACE_STOP
        p, n = _world(drv, g)
        # base: facing the middle of the arc still to go, on the side the face looks to
        r, t = part_transform(drv, joint, (stop - q()) / 2)
        mid = r @ p + t
        side = n if np.linalg.norm(n[:2]) > 0.3 else None
        reach = [(p + n * PRE_CONTACT, quat_z_to(-n))]
        if not (drv.place_base_near(mid, side=side, reach_poses=reach) or drv.place_base_near(p, side=side)
                or drv.place_base_near(p)):
            notes.append("no base pose")
            break
        quat = quat_z_to(-n)
        hover = p + n * (PRE_CONTACT + 0.10)
        reached = drv.reach_planned((p + n * PRE_CONTACT, hover), quat)  # as for grasps
        if not reached and np.dot(drv.site - p, n) < 0.0 and g.beyond_local is not None:
            # the cup is behind the face: round the part's free edge instead of sweeping through it
            rb = d.xmat[g.body].reshape(3, 3)
            edge = d.xpos[g.body] + rb @ g.beyond_local
            drv.goto(edge - n * 0.08, max_steps=120, tol=0.03)
            drv.goto(edge + n * (PRE_CONTACT + 0.10), quat, max_steps=120, tol=0.03)
        if not reached:
            drv.goto(hover, quat, max_steps=220, tol=0.02)
        drv.goto(p + n * PRE_CONTACT, quat, max_steps=120)
        grabbed = False
        for k in range(24):
            p, n = _world(drv, g)
            drv.goto(p + n * (PRE_CONTACT - 0.0025 * k), quat, max_steps=10, tol=0.004)
            if robot.object_distance_to_cup(m, d, name) < robot.SUCTION_RANGE * 0.8:
                grabbed = robot.suction_on(m, d, name, torquescale=0.0)
                if grabbed:
                    break
        if not grabbed:
            notes.append(f"attempt {attempt + 1}: cup did not reach the {'outer' if g.outer else 'inner'} face")
            drv.goto(drv.site + n * 0.08, max_steps=40)
            continue
        why = _drive(drv, joint, stop, tol=tol, max_drag=max_drag)
        if why:
            notes.append(f"attempt {attempt + 1}: {why}")
        robot.suction_off(m, d, name)
        p, n = _world(drv, g)
        dp, drv.dp = drv.dp, 0.004  # back off gently: a fast pull drags a light part along
        if g.outer:
            if not hinge:  # a cup resting on a drawer front's top edge would hook it and pull it out
                held_at = drv.site.copy()
                drv.goto(held_at + np.array([0.0, 0.0, 0.02]), max_steps=10, tol=0.004)
                if _cup_touches(drv, g.body):  # it rose under the handle: leave straight out from where it held
                    drv.goto(held_at, max_steps=10)
            drv.goto(drv.site + n * 0.10, max_steps=40)
        else:  # the inner face looks into the cabinet: leave upwards, over the part's edge
            drv.goto(drv.site + n * 0.03, max_steps=15)
            drv.dp = dp
            drv.goto(drv.site + np.array([0.0, 0.0, 0.25]), max_steps=40)
        drv.dp = dp
    drv.settle(10)
    # lift well clear first, so the arm does not sweep through what it just opened
    drv.straighten_wrist(lift=0.25, lift_steps=60)
    ok = abs(q() - goal) <= tol
    detail = f"{joint} = {q():.3f} (goal {goal:.3f})" + (f"; {'; '.join(notes)}" if notes else "")
    return PrimitiveResult(ok, drv.steps - s0, detail)


def _cup_touches(drv, body: int) -> bool:
    """Is the suction cup in contact with ``body``?"""
    import mujoco

    from anomalygen.scene import robot

    m, d = drv.model, drv.data
    cup = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, robot.CUP_BODY)
    for i in range(d.ncon):
        b1, b2 = int(m.geom_bodyid[d.contact.geom1[i]]), int(m.geom_bodyid[d.contact.geom2[i]])
        if {b1, b2} == {cup, body}:
            return True
    return False


def _drive(drv, joint: str, goal: float, *, tol: float, max_steps: int = 400, max_drag: float = MAX_DRAG) -> str:
    """Lead the held part towards ``goal``: the cup target rides the part's path just ahead of it."""
    import mujoco

    m, d = drv.model, drv.data
    j = m.joint(joint).id
    adr = m.jnt_qposadr[j]
    hinge = m.jnt_type[j] == HINGE
    step = 0.03 if hinge else 0.012  # rad or m the reference advances per control step at most
    # How far the reference may run ahead of the part: small first, so a light box is not dragged
    # along by its lid; it grows while the part does not follow (a heavy oven door), up to 4x.
    lead0 = LEAD_HINGE if hinge else 0.02
    site0 = drv.site.copy()
    cupq0 = d.mocap_quat[drv._mocap].copy()
    q0 = float(d.qpos[adr])
    ref = q0
    root = _object_root(m, int(m.jnt_bodyid[j]))
    root0 = d.xpos[root].copy()  # a lid at its stop drags or tips a light box: stop before it goes far
    best, stall = abs(q0 - goal), 0
    why = ""
    for _ in range(max_steps):
        q = float(d.qpos[adr])
        if abs(q - goal) <= tol * 0.5:
            break
        lead = lead0 * min(4.0, 1.0 + stall / 8)
        if abs(ref - q) < lead:
            ref = ref + np.clip(goal - ref, -step, step)
        r, t = part_transform(drv, joint, ref - q)
        # where the grasped point is now, moved with the part to the reference value
        rq, tq = part_transform(drv, joint, q - q0)
        here = rq @ site0 + tq
        target = r @ here + t
        rot = np.array([1.0, 0.0, 0.0, 0.0])
        if hinge:
            mujoco.mju_mat2Quat(rot, (r @ rq).reshape(9))
        quat = np.zeros(4)
        mujoco.mju_mulQuat(quat, rot, cupq0)
        drv.goto(target, quat, max_steps=1, tol=0.0)
        if np.linalg.norm(d.xpos[root] - root0) > max_drag or d.xmat[root][8] < np.cos(MAX_TILT):
            why = f"stopped: {m.body(root).name} was being dragged or tipped"
            break
        gap = abs(float(d.qpos[adr]) - goal)
        if gap < best - 1e-3:
            best, stall = gap, 0
        else:
            stall += 1
            if stall > 40:
                why = "stopped: the part no longer followed"
                break
    for _ in range(10):  # hold still a moment so the part settles where it was led
        drv.step()
    # Pulling pushes the soft base servo back a little; make where it stands the new set point, or the
    # base would roll forward again afterwards and shove the drawer shut with the arm.
    from anomalygen.scene import robot

    for name in robot.BASE_JOINTS:
        d.actuator(name).ctrl[0] = float(d.joint(name).qpos[0])
    return why


# --------------------------------------------------------------------------- containers
LIDS = ("lid", "flap")
OPEN_FRACTION = 0.85  # how far a lid, flap or drawer is opened to put something in


def closure_joints(drv, obj: str, labels) -> list:
    """The object's JointStates whose label is one of ``labels``."""
    return [js for o in drv.spec.objects if o.name == obj for js in o.joint_states if js.label in labels]


def _far(js) -> float:
    lo, hi = js.range
    return hi if abs(hi - js.closed_value) >= abs(lo - js.closed_value) else lo


def best_drawer(drv, obj: str, drawers: list):
    """The drawer to put things in: the highest one whose top is within the arm's comfortable band."""
    def top(js) -> float:
        return float(drv.aabb(drv.joint_body(js.name))[1][2])

    ok = [js for js in drawers if 0.2 < top(js) < 1.15]
    return max(ok or drawers, key=top) if (ok or drawers) else None


def compartment_behind(drv, obj: str, js) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lo, hi, outward normal) of the space behind a shut door: the door's face extent, as deep as
    the carcass reaches behind it."""
    dlo, dhi = drv.aabb(drv.joint_body(js.name))
    clo, chi = static_box(drv, obj)
    g = grasp_candidates(drv, js.name, js.closed_value)[0]
    n = _world(drv, g)[1]
    k = int(np.argmax(np.abs(n[:2])))
    lo, hi = dlo.copy(), dhi.copy()
    if n[k] < 0:  # the door faces -k: the compartment runs towards +k
        lo[k], hi[k] = dhi[k], chi[k]
    else:
        lo[k], hi[k] = clo[k], dlo[k]
    out = np.zeros(3)
    out[k] = np.sign(n[k])
    return lo, hi, out


def best_door(drv, obj: str, doors: list):
    """The door whose compartment is tall enough for the hand (0.18 m) and the highest within reach."""
    ok = []
    for js in doors:
        if abs(float(drv.data.joint(js.name).qpos[0]) - js.closed_value) > 0.1:
            continue  # only shut doors have a known compartment behind them
        lo, hi, _ = compartment_behind(drv, obj, js)
        if hi[2] - lo[2] >= 0.18 and lo[2] < 1.0:  # low doors too: the object then goes in sideways
            ok.append((float(lo[2]), js))
    return max(ok, key=lambda t: t[0])[1] if ok else None


def _compartment_when_shut(drv, obj: str, js):
    """``compartment_behind`` of a door in whatever state it is: measured with the door put shut for
    the kinematics only (the state is restored, no time passes)."""
    import mujoco

    adr = drv.model.jnt_qposadr[drv.model.joint(js.name).id]
    q = float(drv.data.qpos[adr])
    drv.data.qpos[adr] = js.closed_value
    mujoco.mj_kinematics(drv.model, drv.data)
    try:
        return compartment_behind(drv, obj, js)
    finally:
        drv.data.qpos[adr] = q
        mujoco.mj_forward(drv.model, drv.data)


def holding_closure(drv, obj: str, contents: str):
    """The door or drawer of ``obj`` in front of ``contents``, open or shut: (JointState, compartment
    or None). A fridge has a freezer drawer or door and a main door; the one to open, and the way the
    cup comes in, is the one whose compartment holds the object's centre."""
    lo_c, hi_c = drv.aabb(contents)
    c = (lo_c + hi_c) / 2
    for js in closure_joints(drv, obj, ["door"]):
        lo, hi, out = _compartment_when_shut(drv, obj, js)
        if np.all(c >= lo - 0.03) and np.all(c <= hi + 0.03):
            return js, (lo, hi, out)
    for js in closure_joints(drv, obj, ["drawer"]):
        lo, hi = drv.aabb(drv.joint_body(js.name))
        if np.all(c[:2] >= lo[:2]) and np.all(c[:2] <= hi[:2]) and lo[2] <= c[2] <= hi[2] + 0.05:
            return js, None
    return None


def open_for_access(drv, obj: str, labels, contents: str | None = None):
    """Open the container so an object can go in: every lid and flap, or the best drawer; with
    ``contents`` (an object to take out), the door or drawer in front of that object.

    Records what was opened in ``drv.opened[obj]`` (so the place step drops into an opened drawer
    and the close step shuts exactly these) and returns a PrimitiveResult.
    """

    s0 = drv.steps
    if contents is not None and obj in drv.opened:  # a second attempt: the same part again
        lids = []
        chosen = [js for js in closure_joints(drv, obj, CLOSURES_ALL) if js.name in drv.opened[obj]]
    elif contents is not None:
        found = holding_closure(drv, obj, contents)
        if found is None:
            return PrimitiveResult(True, 0, f"{contents} lies behind no door or drawer of {obj}: nothing to open")
        js, room = found
        if room is not None:
            drv.compartments[obj] = room
            drv.compartment_anchor[obj] = drv.data.xpos[drv.body_id(obj)].copy()
        labels = [js.label]
        lids = []
        chosen = [js]
    else:
        lids = closure_joints(drv, obj, [lab for lab in labels if lab in LIDS])
        chosen = lids
    if not chosen:
        drawer = best_drawer(drv, obj, closure_joints(drv, obj, ["drawer"]))
        chosen = [drawer] if drawer is not None else []
    if not chosen and obj in drv.compartments:
        # a second attempt on a door left part open: the door and its compartment were chosen and
        # measured (shut) the first time; now it is open, best_door would not know it any more
        chosen = [js for js in closure_joints(drv, obj, ["door"]) if js.name in drv.opened.get(obj, [])]
    if not chosen:
        door = best_door(drv, obj, closure_joints(drv, obj, ["door"]))
        if door is None:
            return PrimitiveResult(False, 0, f"{obj} has no lid, flap, drawer or door with a reachable "
                                             "compartment behind it")
        drv.compartments[obj] = compartment_behind(drv, obj, door)
        drv.compartment_anchor[obj] = drv.data.xpos[drv.body_id(obj)].copy()
        chosen = [door]
    drv.opened[obj] = [js.name for js in chosen]
    ok, details = True, []
    for js in chosen:
        goal = js.closed_value + OPEN_FRACTION * (_far(js) - js.closed_value)
        tol = 0.3 * abs(js.range[1] - js.range[0])  # over half open is open enough to put things in
        q = float(drv.data.joint(js.name).qpos[0])
        if abs(q - js.closed_value) < abs(goal - js.closed_value) - tol:
            r = actuate_part(drv, js.name, goal, closed=js.closed_value, tol=tol)
            ok &= r.success
            details.append(r.detail)
        steep = _near_upright(drv, js)
        sgn = np.sign(_far(js) - js.closed_value)
        if ok and steep is not None and (steep - float(drv.data.joint(js.name).qpos[0])) * sgn > 0.1:
            # A lid is held where it is left (hinge friction), and one left half open leans over the
            # opening: a carton lowered in hits it. Lift it on to just short of upright, but give up
            # as soon as the container itself moves (near upright the cup pulls sideways, and a light
            # box slides rather than its stiff lid turning); what it reached is kept.
            before = float(drv.data.joint(js.name).qpos[0])
            r = actuate_part(drv, js.name, steep, closed=js.closed_value, tol=0.05, attempts=2,
                             max_drag=STEEP_MAX_DRAG)
            details.append("lifted on: " + r.detail)
            if (before - float(drv.data.joint(js.name).qpos[0])) * sgn > 0.1:  # knocked back down on the way
                r = actuate_part(drv, js.name, goal, closed=js.closed_value, tol=tol)
                ok &= r.success
                details.append("again: " + r.detail)
    return PrimitiveResult(ok, drv.steps - s0, "opened: " + "; ".join(details) if details else f"{obj} already open")


SHORT_OF_UPRIGHT = 0.15  # rad: how far short of upright a lid is lifted on to
STEEP_MAX_DRAG = 0.03  # m the container may move while its lid is lifted on


def _upright_value(drv, joint: str) -> float | None:
    """Joint value at which a hinged part's centre of mass stands straight above its (horizontal)
    hinge axis; None for a slide or a hinge that is not horizontal."""
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


def _near_upright(drv, js) -> float | None:
    """The value just short of upright for a hinged lid or flap (its own stop if that comes first),
    None for other parts."""
    if js.label not in LIDS:
        return None
    upright = _upright_value(drv, js.name)
    if upright is None:
        return None
    far = _far(js)
    sgn = np.sign(far - js.closed_value)
    if (upright - js.closed_value) * sgn <= 0:
        return None
    steep = upright - sgn * SHORT_OF_UPRIGHT
    return float(far - sgn * 0.05 if (steep - far) * sgn > -0.05 else steep)


def _falls_shut(drv, joint: str, closed: float) -> bool:
    """Would gravity swing this hinged part back towards closed? (its centre of mass is on the
    closed side of the vertical plane through the hinge axis)"""
    m, d = drv.model, drv.data
    j = m.joint(joint).id
    body = int(m.jnt_bodyid[j])
    axis = d.xaxis[j]
    q = float(d.qpos[m.jnt_qposadr[j]])
    torque = float(np.dot(np.cross(d.xipos[body] - d.xanchor[j], np.array([0.0, 0.0, -1.0])), axis))
    # gravity torque along the axis pushes q towards closed when its sign opposes the opening direction
    return bool(torque * np.sign(q - closed) < 0)


def close_opened(drv, obj: str, *, every: bool = False):
    """Shut the parts ``open_for_access`` opened on ``obj`` (hinged lids last-opened first); with
    ``every``, also the ones found open (a fridge the object came out of: every door it has)."""

    s0 = drv.steps
    names = list(reversed(drv.opened.get(obj, [])))
    if every:
        names += [js.name for js in closure_joints(drv, obj, CLOSURES_ALL) if js.name not in names]
    ok, details = True, []
    for js in closure_joints(drv, obj, CLOSURES_ALL):
        if js.name not in names:
            continue
        tol = 0.025 * abs(js.range[1] - js.range[0])
        if abs(float(drv.data.joint(js.name).qpos[0]) - js.closed_value) <= tol:
            continue
        r = actuate_part(drv, js.name, js.closed_value, closed=js.closed_value, tol=tol)
        ok &= r.success
        details.append(r.detail)
    return PrimitiveResult(ok, drv.steps - s0, "; ".join(details) or f"nothing of {obj} left open")


CLOSURES_ALL = ("lid", "flap", "drawer", "door")
