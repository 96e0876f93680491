"""Grasp-and-drive primitive for articulated parts: doors, lids, flaps and drawers.

Pushing a part with the cup cannot open anything, cannot lift a fold-down oven door and
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

from anomalygen.robot.agent import Agent
from anomalygen.robot.frames import subtree_geoms
from anomalygen.skills.episode import Episode
from anomalygen.skills.geometry import HINGE, PRE_CONTACT, SLIDE, body_corners, static_box
from anomalygen.skills.registry import SkillOutcome

INNER_FACE_STOP = 0.4  # rad: a grasp on the inner face lets go this far from closed
LEAVE_UNDER = 0.06  # m past a lid's free edge the cup moves, from under the lid it let go of, before it rises
MAX_LEAVE_UNDER = 0.4  # m it moves at most
LEAD_HINGE = 0.06
MAX_DRAG = 0.10  # m the container may be dragged by its part before the drive gives up
MAX_TILT = 0.35  # rad it may tip
COMFORT_Z = 0.95  # m: height at which the arm holds a tall door
LID_EDGE_INSET = 0.035  # m from a lid's free edge to the cup's centre (the cup is 0.02 m in radius)


@dataclass
class PartGrasp:
    body: int
    point_local: np.ndarray  # grasp point, part body frame
    normal_local: np.ndarray  # outward normal of the grasped face, part body frame
    outer: bool  # the face that points out of the cabinet when closed
    beyond_local: np.ndarray | None = None  # just past the free edge (hinged parts), part body frame
    lid: bool = False  # a panel lying flat when shut, on a horizontal hinge


def _rot(axis: np.ndarray, angle: float) -> np.ndarray:
    a = axis / (np.linalg.norm(axis) + 1e-12)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * (k @ k)


def part_transform(ep: Episode, joint: str, dq: float):
    """(R, t) moving a world point with the part when the joint value changes by ``dq``."""
    drv = ep.driver
    m, d = drv.model, drv.data
    j = m.joint(joint).id
    axis = d.xaxis[j].copy()
    if m.jnt_type[j] == SLIDE:
        return np.eye(3), axis / np.linalg.norm(axis) * dq
    r = _rot(axis, dq)
    anchor = d.xanchor[j]
    return r, anchor - r @ anchor


def _body_box(ep: Episode, body: int) -> tuple[np.ndarray, np.ndarray]:
    """Local AABB (body frame) of the body's own collision geoms (all geoms if none collide)."""
    import mujoco

    drv = ep.driver
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


def grasp_candidates(ep: Episode, joint: str, closed: float) -> list[PartGrasp]:
    """The outer and the inner face of the part, with a grasp point each (outer first)."""
    drv = ep.driver
    m, d = drv.model, drv.data
    j = m.joint(joint).id
    body = int(m.jnt_bodyid[j])
    lo, hi = _body_box(ep, body)
    rb = d.xmat[body].reshape(3, 3)
    q = float(d.qpos[m.jnt_qposadr[j]])
    rc, tc = part_transform(ep, joint, closed - q)  # current -> closed pose
    clo, chi = static_box(ep, m.body(_object_root(m, body)).name)
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
    lid = False
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
            lid = bool(abs(axis_w[2]) < 0.3 and abs((rc @ rb[:, k])[2]) > 0.7)
            if lid:
                # a lid (a panel lying flat when shut, on a horizontal hinge) is held near its free
                # edge: a lid that reaches past the cup rises into the wrist as it turns, and the wrist,
                # pressed down on it, shoves the container along (a trash can slid 4 cm and the lid
                # stopped at 1 rad)
                edge = far - np.sign(far - anchor_l[i_far]) * LID_EDGE_INSET
                if abs(edge - anchor_l[i_far]) > abs(p_l[i_far] - anchor_l[i_far]):
                    p_l[i_far] = edge
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
        out.append(PartGrasp(body, p_l, n_l, outer=outer, beyond_local=beyond, lid=lid))
    out.sort(key=lambda g: not g.outer)
    return out


def _world(ep: Episode, g: PartGrasp) -> tuple[np.ndarray, np.ndarray]:
    drv = ep.driver
    d = drv.data
    rb = d.xmat[g.body].reshape(3, 3)
    return d.xpos[g.body] + rb @ g.point_local, rb @ g.normal_local


def _on_surface(ep: Episode, g: PartGrasp) -> PartGrasp:
    """Move the grasp point onto the part's real surface along the face normal (a ray): the box of a
    door with a handle has its front face at the handle's tip, centimetres in front of the panel."""
    import mujoco


    drv = ep.driver
    m, d = drv.model, drv.data
    p, n = _world(ep, g)
    part = subtree_geoms(m, g.body)
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
            return PartGrasp(g.body, rb.T @ (hit - d.xpos[g.body]), g.normal_local, g.outer, g.beyond_local, g.lid)
        travelled += dist + 1e-4
        start = hit - n * 1e-4
    return g


def _accessible(n_w: np.ndarray) -> bool:
    """A face the cup can come at: not facing the floor."""
    return bool(n_w[2] > -0.5)


def _joint_of(m, joint: str) -> tuple[int, int, bool]:
    """A joint's id, its qpos address and whether it is a hinge (else a slide)."""
    j = m.joint(joint).id
    return j, int(m.jnt_qposadr[j]), bool(m.jnt_type[j] == HINGE)


BASE_IN_FRONT = 0.10  # m the base's centre stands in front of a steep face's plane for the arm to come at it


def _faces_base(ep: Episode, g: PartGrasp) -> bool:
    """Does the arm come at the face from the side it looks to? A steep face whose plane the base
    stands behind (a lid leaning back past upright, its outer face towards a wall) is reached only
    by wrapping the arm round the panel, and the arm sweeping past shoves it open on its stop,
    which tips a light box over backwards. Lids only: a door's inner face is held only to 0.4 rad
    from shut, and choosing it for an open fridge door left the door open."""
    p, n = _world(ep, g)
    if not g.lid or abs(n[2]) >= 0.5 or np.linalg.norm(n[:2]) < 1e-6:
        return True
    base = ep.driver.agent.base_pose(ep.driver.data)[:2]
    return float(np.dot(base - p[:2], n[:2] / np.linalg.norm(n[:2]))) > BASE_IN_FRONT


def _place_base_for(ep: Episode, joint: str, g: PartGrasp, goal: float, closed: float) -> tuple[float, bool]:
    """(where the drive stops for this face, whether a base pose was found): the base faces the middle
    of the arc still to go, on the side the face looks to."""
    from anomalygen.robot.ik import quat_z_to

    drv = ep.driver
    m, d = drv.model, drv.data
    _, adr, hinge = _joint_of(m, joint)
    q = float(d.qpos[adr])
    stop = goal
    if not g.outer and hinge and abs(goal - closed) < INNER_FACE_STOP:
        stop = closed + np.sign(q - closed) * INNER_FACE_STOP
    p, n = _world(ep, g)
    r, t = part_transform(ep, joint, (stop - q) / 2)
    mid = r @ p + t
    side = n if np.linalg.norm(n[:2]) > 0.3 else None
    reach = [(p + n * PRE_CONTACT, quat_z_to(-n))]
    arc = []
    if g.lid:  # the cup turns with a lid: a base from which the arm follows the arc to its end, cup
        # on the face all the way (from the free edge's side the wrist cannot tip back far enough and
        # presses on the lid; from the hinge axis's end it is a roll of the wrist)
        for f in (0.5, 1.0):
            r_f, t_f = part_transform(ep, joint, (stop - q) * f)
            arc.append((r_f @ p + t_f + r_f @ n * PRE_CONTACT, quat_z_to(-(r_f @ n))))
    placed = drv.place_base_near(mid, side=side, reach_poses=reach + arc)
    if placed and arc and not drv.reaches:  # no base follows the whole arc: one that reaches the lid
        placed = drv.place_base_near(mid, side=side, reach_poses=reach)
    return stop, bool(placed or drv.place_base_near(p, side=side) or drv.place_base_near(p))


def actuate_part(ep: Episode, joint: str, goal: float, *, closed: float, tol: float = 0.02, attempts: int = 4,
                 max_steps: int = 900, max_drag: float = MAX_DRAG):
    """Hold the part by suction and lead it to ``goal``; re-grasp when it stops following."""
    from anomalygen.robot.ik import quat_z_to

    drv = ep.driver
    m, d = drv.model, drv.data
    j, adr, hinge = _joint_of(m, joint)
    s0 = drv.steps
    name = m.body(int(m.jnt_bodyid[j])).name
    notes = []

    def q() -> float:
        return float(d.qpos[adr])

    missed: set[bool] = set()  # faces (outer or not) the cup failed to reach since the part last moved
    for attempt in range(attempts):
        if abs(q() - goal) <= tol or drv.steps - s0 > max_steps:
            break
        grasps = [g for g in grasp_candidates(ep, joint, closed) if _accessible(_world(ep, g)[1])]
        if not grasps:
            notes.append("no reachable face")
            break
        # a face the cup could not get at is tried again only after the other: a door swung onto its
        # stop shows its outer face to whatever stands behind it, yet its inner face brings it back
        grasps = [g for g in grasps if g.outer not in missed] + [g for g in grasps if g.outer in missed]
        for g in [_on_surface(ep, c) for c in grasps] + [_on_surface(ep, grasps[0])]:
            stop, placed = _place_base_for(ep, joint, g, goal, closed)
            if placed and _faces_base(ep, g):
                break
        if not placed:
            notes.append("no base pose")
            break
        p, n = _world(ep, g)
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
            p, n = _world(ep, g)
            drv.goto(p + n * (PRE_CONTACT - 0.0025 * k), quat, max_steps=10, tol=0.004)
            if drv.agent.cup_distance(d, name) < drv.agent.SUCTION_RANGE * 0.8:
                grabbed = drv.agent.grab(d, name)
                if grabbed:
                    break
        if not grabbed:
            notes.append(f"attempt {attempt + 1}: cup did not reach the {'outer' if g.outer else 'inner'} face")
            missed.add(g.outer)
            drv.goto(drv.site + n * 0.08, max_steps=40)
            continue
        missed.clear()
        why = _drive(ep, joint, stop, tol=tol, max_drag=max_drag)
        if why:
            notes.append(f"attempt {attempt + 1}: {why}")
        _slacken(ep)
        drv.agent.release(d, name)
        p, n = _world(ep, g)
        dp, drv.dp = drv.dp, 0.004  # back off gently: a fast pull drags a light part along
        if g.outer:
            if not hinge:  # a cup resting on a drawer front's top edge would hook it and pull it out
                held_at = drv.site.copy()
                drv.goto(held_at + np.array([0.0, 0.0, 0.02]), max_steps=10, tol=0.004)
                if _cup_touches(ep, g.body):  # it rose under the handle: leave straight out from where it held
                    drv.goto(held_at, max_steps=10)
            drv.goto(drv.site + n * 0.10, max_steps=40)
        else:  # the inner face looks into the cabinet: leave upwards, over the part's edge
            drv.goto(drv.site + n * 0.03, max_steps=15)
            drv.dp = dp
            if hinge and n[2] < -0.3 and np.linalg.norm(n[:2]) > 1e-6:
                # a lid led nearly shut from inside: the cup is under it, and rising straight up lifted
                # a bin's lid from 0.41 to 0.67 rad open; first out from under it, past its free edge
                u = np.array([*(n[:2] / np.linalg.norm(n[:2])), 0.0])
                past = float(np.max((body_corners(ep, g.body) - drv.site) @ u)) + LEAVE_UNDER
                drv.goto(drv.site + u * min(past, MAX_LEAVE_UNDER), max_steps=60)
            drv.goto(drv.site + np.array([0.0, 0.0, 0.25]), max_steps=40)
        drv.dp = dp
    drv.settle(10)
    # lift well clear first, so the arm does not sweep through what it just opened
    drv.straighten_wrist(lift=0.25, lift_steps=60)
    ok = abs(q() - goal) <= tol
    detail = f"{joint} = {q():.3f} (goal {goal:.3f})" + (f"; {'; '.join(notes)}" if notes else "")
    return SkillOutcome(ok, drv.steps - s0, detail)


SLACKEN_STEPS = 15  # control steps the arm holds still, its target on the cup, before letting go of a part


def _slacken(ep: Episode) -> None:
    """Stop leading the held part before letting go: the drive keeps the arm's target ahead of the
    cup, and the wrist pressed on the panel pushes back against the suction weld; let go under that
    strain, a light safe door sprang back shut at 1.2 rad/s. The target moved onto the cup, the
    strain goes while the cup still holds the part."""
    drv = ep.driver
    d = drv.data
    cup = drv.agent.cup
    for _ in range(SLACKEN_STEPS):
        d.mocap_pos[drv._mocap] = d.xpos[cup]
        d.mocap_quat[drv._mocap] = d.xquat[cup]
        drv.step()


def _cup_touches(ep: Episode, body: int) -> bool:
    """Is the suction cup in contact with ``body``?"""
    import mujoco


    drv = ep.driver
    m, d = drv.model, drv.data
    cup = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, Agent.CUP_BODY)
    for i in range(d.ncon):
        b1, b2 = int(m.geom_bodyid[d.contact.geom1[i]]), int(m.geom_bodyid[d.contact.geom2[i]])
        if {b1, b2} == {cup, body}:
            return True
    return False


def _drive(ep: Episode, joint: str, goal: float, *, tol: float, max_steps: int = 400, max_drag: float = MAX_DRAG) -> str:
    """Lead the held part towards ``goal``: the cup target rides the part's path just ahead of it."""
    import mujoco

    drv = ep.driver
    m, d = drv.model, drv.data
    j, adr, hinge = _joint_of(m, joint)
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
        r, t = part_transform(ep, joint, ref - q)
        # where the grasped point is now, moved with the part to the reference value
        rq, tq = part_transform(ep, joint, q - q0)
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

    for name in Agent.BASE_JOINTS:
        d.actuator(name).ctrl[0] = float(d.joint(name).qpos[0])
    return why
