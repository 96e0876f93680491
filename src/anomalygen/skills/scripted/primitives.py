"""Motion primitives: approach, grasp, side grasp, release, move and place (into a container, onto a
support, through an opened door).

Each one runs in an :class:`~anomalygen.skills.episode.Episode` (moving the robot through its
:class:`~anomalygen.robot.driver.Driver`) and returns a ``SkillOutcome``; the scene geometry they aim
at comes from :mod:`~anomalygen.skills.geometry`; :mod:`~anomalygen.skills.scripted.actions` registers
them as skills. They need no learned policy: the scene says where to go.
"""

from __future__ import annotations

import numpy as np

from anomalygen.mjgeom import geom_world_aabbs
from anomalygen.robot.agent import Agent
from anomalygen.robot.frames import subtree_geoms
from anomalygen.skills.episode import Episode
from anomalygen.skills.geometry import (
    PRE_CONTACT,
    drop_point,
    floor_below,
    footprint,
    free_spot,
    grasp_points,
    lid_free_side,
    long_axis_yaw,
    opening,
    rim_z,
    top_rect,
)
from anomalygen.skills.registry import SkillOutcome
from anomalygen.skills.scripted.laydown import (
    LAY_DOWN_OUT,
    beside,
    depth_inside,
    lay_on_side,
    tip_direction_for_lid,
    too_tall_to_go_in,
)
from anomalygen.skills.scripted.setdown import (
    centre_over,
    let_swing_die,
    lower_until_contact,
    turn_until_there,
)

GRASP_POINTS = 5  # a 1 m cord in a bathtub: only its 4th point is in reach over the tub's rim
LOW_CUP = 0.1  # m: a cup this far below the grasp point is tucked in before the base moves


def approach(ep: Episode, obj: str, point=None) -> SkillOutcome:
    """Base near ``obj``, cup to 0.03 m above its top face (grasp ``point``), cup facing the surface.

    The pre-contact pose is reached by IK and a collision-free joint path (``arm_motion``), as the
    paper does; when planning fails the cup rises and comes down straight instead."""
    from anomalygen.robot.ik import quat_z_to

    drv = ep.driver
    s0 = drv.steps
    normal = np.array([0.0, 0.0, 1.0])
    point = grasp_points(ep, obj)[0] if point is None else point
    quat = quat_z_to(-normal)
    pre = point + normal * PRE_CONTACT
    hover = point + normal * (PRE_CONTACT + 0.12)
    if drv.held is None and drv.site[2] < point[2] - LOW_CUP:
        # the cup is low (it just pulled a safe's door near the floor): fold the arm in before the base
        # moves, or the base carries it under the table the object stands on and it cannot rise (t0029)
        drv.tuck()
    # a base pose from which the cup reaches the object face-down (a globe's top is 1.2 m up: from
    # the wrong spot the cup meets it tilted and the globe hangs crooked)
    if not drv.place_base_near(point, reach_poses=[(pre, quat), (hover, quat)]):
        return SkillOutcome(False, drv.steps - s0, f"no collision-free base pose near {obj}")
    planned = drv.reach_planned((pre, hover), quat)  # the hover pose is freer when pre-contact is cramped
    if not planned:  # rise, turn the cup face-down while clear of everything, then come over and down
        drv.straighten_wrist()
        up = drv.site + np.array([0, 0, max(0.0, hover[2] - drv.site[2])])
        drv.goto(up, max_steps=120)
        drv.goto(up, quat, max_steps=60)
        drv.goto(hover, quat, max_steps=200)
    ok = drv.goto(pre, quat, max_steps=200)
    return SkillOutcome(ok, drv.steps - s0, f"pre-contact {'reached' if ok else 'not reached'} above {obj}")


def grasp(ep: Episode, obj: str, *, lift: float = 0.12) -> SkillOutcome:
    """Approach, move along the normal until the cup touches, switch suction on, lift by ``lift``.

    Tries up to GRASP_POINTS grasp points (``grasp_points``) before giving up; a point with no base
    pose from which the arm reaches it is passed over, not the end of the grasp."""
    from anomalygen.robot.ik import quat_z_to

    drv = ep.driver
    s0 = drv.steps
    normal = np.array([0.0, 0.0, 1.0])
    quat = quat_z_to(-normal)
    grabbed, tried_side, no_base, based = False, False, None, False
    for point in grasp_points(ep, obj, n=GRASP_POINTS):
        res = approach(ep, obj, point)
        if not res.success and "base" in res.detail:
            # no base pose for this point: another may have one (the far end of a cord in a bathtub)
            no_base = no_base or res
            continue
        based = True  # a point had a base pose: a failure is the cup's, not the base's
        if (not drv.reaches and not tried_side and drv.aabb(obj)[1][2] - drv.aabb(obj)[0][2] > 0.2
                and footprint(ep, obj)[2] > 0.09):  # bulky, not a thin screen that a side push would topple
            # a tall object whose top the cup cannot reach face-down: hold it by the side if possible
            tried_side = True
            side = side_grasp(ep, obj, lift=lift)
            if side.success:
                return SkillOutcome(True, drv.steps - s0, side.detail)
            drv.straighten_wrist(lift=0.1)  # back from the side pose before trying the top
            res = approach(ep, obj, point)
        for k in range(40):  # descend 2.5 mm per waypoint until suction catches
            target = point + normal * (PRE_CONTACT - 0.0025 * k)
            drv.goto(target, quat, max_steps=12, tol=0.004)
            if drv.agent.cup_distance(drv.data, obj) < drv.agent.SUCTION_RANGE * 0.8:
                grabbed = drv.agent.grab(drv.data, obj)
                if grabbed:
                    break
        if grabbed:
            break
        drv.goto(drv.site + normal * 0.06, quat, max_steps=40)
    if not grabbed and not based and no_base is not None:
        return no_base  # no point had a base pose
    if not grabbed:
        return SkillOutcome(False, drv.steps - s0, f"suction did not catch {obj} "
                               f"(cup-object distance {drv.agent.cup_distance(drv.data, obj):.3f} m)")
    drv.goto(drv.site + np.array([0, 0, lift]), quat, max_steps=150)
    return SkillOutcome(True, drv.steps - s0, f"holding {obj}, lifted {lift:.2f} m")


def side_grasp(ep: Episode, obj: str, *, lift: float = 0.12) -> SkillOutcome:
    """Hold a tall object by the side of its widest part, cup horizontal (a globe's top is beyond
    the arm's reach with the cup face-down). The cup comes from the robot's side along a ray to the
    surface; the weld then holds the object's body, so it is carried upright."""
    import mujoco

    from anomalygen.robot.ik import quat_z_to

    drv = ep.driver
    s0 = drv.steps
    m, d = drv.model, drv.data
    glo, ghi = geom_world_aabbs(m, d)
    mask = subtree_geoms(m, drv.body_id(obj)) & (m.geom_contype | m.geom_conaffinity).astype(bool)
    g = max(np.flatnonzero(mask), key=lambda k: float(np.prod(ghi[k, :2] - glo[k, :2])))
    centre = (glo[g] + ghi[g]) / 2
    base = np.array([float(d.joint(j).qpos[0]) for j in Agent.BASE_JOINTS[:2]])
    a0 = float(np.arctan2(*(base - centre[:2])[::-1]))
    geomid = np.zeros(1, dtype=np.int32)
    for a in a0 + np.array([0, 1, -1, 2, -2, 3, -3, 4]) * np.pi / 4:  # from the robot's side first
        n = np.array([np.cos(a), np.sin(a), 0.0])
        quat = quat_z_to(-n)
        dist = mujoco.mj_ray(m, d, centre + n * 0.5, -n, None, 1, -1, geomid)
        if dist < 0 or not mask[int(geomid[0])]:
            continue  # something else stands in front of the object on this side
        point = centre + n * (0.5 - dist)
        pre = point + n * PRE_CONTACT
        if drv.place_base_near(point, side=n, reach_poses=[(pre, quat), (pre + n * 0.1, quat)]) and drv.reaches:
            break
    else:
        return SkillOutcome(False, drv.steps - s0, f"no base pose reaches the side of {obj}")
    if not drv.reach_planned((pre, pre + n * 0.1), quat):
        drv.goto(drv.site + np.array([0, 0, max(0.0, pre[2] + 0.1 - drv.site[2])]), max_steps=100)
        drv.goto(pre + n * 0.1, quat, max_steps=250, tol=0.02)
    drv.goto(pre, quat, max_steps=150)
    for k in range(40):
        drv.goto(point + n * (PRE_CONTACT - 0.0025 * k), quat, max_steps=10, tol=0.004)
        if drv.agent.cup_distance(d, obj) < drv.agent.SUCTION_RANGE * 0.8 and drv.agent.grab(d, obj):
            drv.goto(drv.site + np.array([0, 0, lift]), quat, max_steps=150)
            return SkillOutcome(True, drv.steps - s0, f"holding {obj} by its side, lifted {lift:.2f} m")
    drv.goto(drv.site + n * 0.08, quat, max_steps=40)
    return SkillOutcome(False, drv.steps - s0, f"suction did not catch the side of {obj}")


def release(ep: Episode) -> SkillOutcome:
    drv = ep.driver
    s0 = drv.steps
    held = drv.held
    drv.agent.release(drv.data)
    drv.settle(15)
    return SkillOutcome(held is not None, drv.steps - s0, f"released {held}" if held else "nothing held")


def _yawed(quat: np.ndarray, yaw: float) -> np.ndarray:
    import mujoco

    out = np.zeros(4)
    mujoco.mju_mulQuat(out, np.array([np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2)]), quat)
    return out


def move_to(ep: Episode, obj: str, region: str, *, release_after: bool = True, into: bool = True,
            away: tuple | None = None, pose: tuple[np.ndarray, float] | None = None) -> SkillOutcome:
    """Carry the held ``obj`` above ``region`` and lower it: into a container's opening (``into``) or
    onto a free spot of a support's top (``away``: at least a gap from a box, see ``free_spot``);
    then release. ``pose`` = (spot, turn) sets it down with its box centred over ``spot`` after
    turning it ``turn`` rad about the vertical (a pan turned with its handle inward)."""
    from anomalygen.robot.ik import quat_z_to

    drv = ep.driver
    s0 = drv.steps
    if drv.held != obj:
        return SkillOutcome(False, 0, f"{obj} is not held")
    if into and region in ep.memory.compartments:
        return place_through_door(ep, obj, region, release_after=release_after)
    laid, tried = "", False
    for sign in (1.0, -1.0):
        # towards the robot first; where the arm cannot turn the cup far enough (a wall close behind
        # the spot) the object lands upright and is taken again, and the other side is tried
        out = tip_direction_for_lid(ep, obj, region) if into and drv.held == obj else None
        if out is None:
            break
        tried = True
        if lay_on_side(ep, obj, beside(ep, region, sign * out), sign * out, lambda: grasp(ep, obj).success):
            laid = "laid on its side, "
            break
    if tried and not laid:
        return SkillOutcome(False, drv.steps - s0, f"{obj} stands taller than {region} is deep and was not "
                                                   "laid on its side and taken again")
    face_down = drv.cup_down(0.7)
    yaw, a, b = footprint(ep, obj)
    # Turn the object so its long side runs along the long side of the opening (or of the table top),
    # but only when it hangs below a face-down cup and, on a table, has a long side: a turn swings a
    # side-held globe so that it lands tilted, and gains nothing for a square camera.
    turning = face_down and (into or a > SQUARE_RATIO * b)
    if pose is not None:
        goal = np.asarray(pose[0], dtype=float)
    else:
        goal = drop_point(ep, region, obj) if into else free_spot(ep, region, obj, turned=turning, away=away)
    aim, short = goal.copy(), np.zeros(2)
    if not into and ep.memory.set_down_error.get(obj, ("", None))[0] == region:
        # a second try at the same set-down: the last one came to rest off the spot (a tall clock
        # held off its middle leans on the way down and settles a few cm further out); aim short
        short = ep.memory.set_down_error[obj][1]
        aim[:2] -= short
    olo, ohi = drv.aabb(obj)
    below = drv.site[2] - olo[2]  # cup face to object bottom
    # carry face-down, or as held for a side grasp (turning the cup would turn the object over)
    quat = quat_z_to(np.array([0.0, 0.0, -1.0])) if face_down else drv.data.mocap_quat[drv._mocap].copy()
    lo, hi = opening(ep, region) if into else top_rect(ep, region)
    # carried high enough that the object's bottom clears the container's rim (a box on a counter is
    # deeper than the 0.1 m above its floor that the set-down point gives)
    rim = rim_z(ep, region) if into else hi[2]
    carry_z = max(drv.site[2], goal[2] + below + 0.1, rim + below + 0.05)
    drv.goto(np.array([*drv.site[:2], carry_z]), quat, max_steps=150)
    want = 0.0 if hi[0] - lo[0] >= hi[1] - lo[1] else np.pi / 2
    turn = (want - yaw + np.pi / 2) % np.pi - np.pi / 2 if turning else 0.0
    if pose is not None:
        turn = float(pose[1])
    final = _yawed(quat, turn)
    # Aim the object, not the cup: held by its side (or off-centre), the object's centre is well away
    # from the cup, so the base is placed for the cup poses that put the object's centre on the goal.
    olo, ohi = drv.aabb(obj)
    off = (olo[:2] + ohi[:2]) / 2 - drv.site[:2]
    off = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]]) @ off
    cup_goal = np.array([*(aim[:2] - off), goal[2]])
    above, low = np.array([*cup_goal[:2], carry_z]), cup_goal + np.array([0, 0, below])
    side = lid_free_side(ep, region) if into else None
    # how low the object may hang: held askew by its side it turns on the way (its longest side, then)
    hang = below if face_down else max(below, float(np.max(ohi - olo)))
    low_carry = max(goal[2] + below + 0.1, rim + below + 0.05, drv.aabb(region)[1][2] + hang + 0.05)
    for lower in (False, True):
        if lower:  # carried high (off a 1.2 m shelf) the pose over the spot is out of reach, and the arm,
            # stretching for it, dragged the base into the bin: carry it only as high as the container
            # asks (its open lid included: the wrist swept through a lid standing 0.3 m over the rim)
            above[2] = low_carry
        if not ((side is not None and drv.place_base_near(cup_goal, side=side, reach_poses=[(above, final), (low, final)]))
                or drv.place_base_near(cup_goal, reach_poses=[(above, final), (low, final)])):
            return SkillOutcome(False, drv.steps - s0, f"no collision-free base pose near {region}")
        if drv.reaches or above[2] <= low_carry + 0.05:
            break
    if not drv.reach_planned((above,), final):
        drv.goto(above, quat, max_steps=250)
        for f in np.linspace(0.2, 1.0, 5):
            drv.goto(above, _yawed(quat, f * turn), max_steps=8)
    quat = final
    let_swing_die(ep, obj)
    below = drv.site[2] - drv.aabb(obj)[0][2]  # again: the swing and the turn change how the object hangs
    low = np.array([low[0], low[1], goal[2] + below])
    # correct what is left of the object's offset from the spot (the base pose only approximates it)
    above, low = centre_over(ep, obj, aim, above, low, quat)
    hover = rim + drv.site[2] - drv.aabb(obj)[0][2] + 0.04  # the object's bottom 4 cm over the rim
    if into and hover < above[2] - 0.1:
        # and again just over the rim: carried down from high up (a carton off a 1.2 m shelf, held
        # askew) the wrist turns on the way and the object came down 8 cm off, onto the lid
        drv.goto(np.array([*above[:2], hover]), quat, max_steps=200, tol=0.01)
        let_swing_die(ep, obj)
        above, low = centre_over(ep, obj, aim, np.array([*above[:2], hover]), low, quat)
    ok = lower_until_contact(ep, obj, low, quat)
    if release_after:
        release(ep)
        drv.goto(drv.site + np.array([0, 0, 0.1]), quat, max_steps=60)
        if not into:
            olo, ohi = drv.aabb(obj)
            miss = short + (olo[:2] + ohi[:2]) / 2 - goal[:2]
            if np.linalg.norm(miss) < MAX_SET_DOWN_CORRECTION:
                ep.memory.set_down_error[obj] = (region, miss)
    return SkillOutcome(ok, drv.steps - s0, f"{obj} {laid}{'lowered' if ok else 'not fully lowered'} over {region}")


def _compartment(ep: Episode, region: str):
    """(lo, hi, outward normal) of the compartment behind ``region``'s opened door, where the container
    stands now (it was measured with the door shut; pulling the door can slide a light safe)."""
    drv = ep.driver
    lo, hi, out = ep.memory.compartments[region]
    anchor = ep.memory.compartment_anchor.get(region)
    shift = np.zeros(3) if anchor is None else drv.data.xpos[drv.body_id(region)] - anchor
    shift[2] = 0.0
    return lo + shift, hi + shift, out


def place_through_door(ep: Episode, obj: str, region: str, *, release_after: bool = True) -> SkillOutcome:
    """Slide the held object into the compartment behind an opened door and set it on its floor.

    The cup stays face-down, so the object is carried level at a height just clearing the
    compartment's floor, turned to lie across the opening, pushed in horizontally, lowered until it
    touches, released; the cup then backs out the way it came."""
    from anomalygen.robot.ik import quat_z_to

    drv = ep.driver
    s0 = drv.steps
    lo, hi, out = _compartment(ep, region)
    centre = (lo + hi) / 2
    # the floor seen from the compartment's middle: a ray started just under the door's top edge starts
    # inside a safe's 3 cm top wall and reports the wall's underside as the floor (the object then
    # ended on the safe's top)
    floor = floor_below(ep, centre, obj)
    floor = float(lo[2]) if floor is None else floor
    if hi[2] - lo[2] < FACE_DOWN_ROOM:
        return _place_sideways(ep, obj, region, floor, release_after=release_after)
    olo, ohi = drv.aabb(obj)
    below = drv.site[2] - olo[2]
    quat = quat_z_to(np.array([0.0, 0.0, -1.0]))
    across = 0.0 if abs(out[0]) > abs(out[1]) else np.pi / 2  # long side along the opening's width
    depth = float(np.dot(hi - lo, np.abs(out)))
    width = float(np.dot(hi - lo, np.abs(np.array([out[1], out[0], 0.0]))))
    yaw, half_long, _ = footprint(ep, obj)
    # ... unless it fills the opening's width and fits the depth: a 0.40 m towel across one door of a
    # cabinet (0.48 m) caught the frame on both sides; turned, it goes in along the 0.76 m depth
    lengthwise = 2 * half_long + 2 * SIDE_ROOM > width and 2 * half_long + SIDE_ROOM <= depth
    turn = (across + (0.0 if lengthwise else np.pi / 2) - yaw + np.pi / 2) % np.pi - np.pi / 2
    final = _yawed(quat, turn)
    z = floor + below + ENTER_CLEARANCE
    inside = np.array([centre[0], centre[1], z])
    front = inside + out * (depth / 2 + 0.2)
    drv.goto(np.array([*drv.site[:2], max(drv.site[2], z + 0.1)]), quat, max_steps=150)
    ok = _enter_and_set_down(ep, obj, front, inside, final, out, np.array([0, 0, 0.01]), release_after, floor=floor)
    if ok is None:
        return SkillOutcome(False, drv.steps - s0, f"no base pose in front of {region}'s open door")
    olo, ohi = drv.aabb(obj)  # the cup stopped short, but what it carried may be all the way in
    ok = ok or bool(np.all(olo[:2] >= lo[:2] - 0.01) and np.all(ohi[:2] <= hi[:2] + 0.01))
    return SkillOutcome(ok, drv.steps - s0, f"{obj} {'slid into' if ok else 'not fully into'} {region} through its door")


def _enter_and_set_down(ep: Episode, obj: str, front, inside, quat, out, backoff, release_after: bool,
                        floor: float | None = None) -> bool | None:
    """Through an opening: base in front of it, the held object carried level from ``front`` to
    ``inside``, lowered until it touches, let go (``backoff``: the cup's first move off it) and the cup
    out the way it came. True when the object got all the way in; None when no base pose reaches.
    With the compartment's ``floor``, the object is raised at ``front`` until its lowest point clears
    it: a towel held off its middle hangs tilted, and its low edge ran into a cabinet's bottom panel."""
    drv = ep.driver
    if not drv.place_base_near(front, side=out, reach_poses=[(front, quat), (inside, quat)]):
        return None
    drv.goto(np.array([*front[:2], max(drv.site[2], inside[2])]), quat, max_steps=250)
    drv.goto(front, quat, max_steps=150)
    if floor is not None:
        let_swing_die(ep, obj)
        rise = floor + ENTER_CLEARANCE - float(drv.aabb(obj)[0][2])
        if rise > 0:
            front, inside = front + np.array([0, 0, rise]), inside + np.array([0, 0, rise])
            drv.goto(front, quat, max_steps=60)
    ok = drv.goto(inside, quat, max_steps=200, tol=0.02)
    lower_until_contact(ep, obj, inside - np.array([0, 0, 0.05]), quat)
    if release_after:
        release(ep)
        drv.goto(drv.site + backoff, quat, max_steps=20)
        drv.goto(np.array([*front[:2], drv.site[2]]), quat, max_steps=150)
    return ok


SIDE_ROOM = 0.05  # m a thing carried through a door keeps from the opening's sides
ENTER_CLEARANCE = 0.015  # m the held object's lowest point clears a compartment's floor going in
FACE_DOWN_ROOM = 0.35  # m of headroom over a compartment's floor below which a face-down hand does not fit
# (the wrist and forearm stand ~0.2 m above the cup: a pill bottle carried face-down into a 0.25 m safe
# dragged along its top and ended on the safe)


def _place_sideways(ep: Episode, obj: str, region: str, floor: float, *, release_after: bool = True) -> SkillOutcome:
    """Put the held object through a low door (a safe, a medicine cabinet) with the cup pointing in.

    The object, turned so its long side runs across the opening, is tipped 90 degrees about that
    side's axis in free space, so it lies ahead of a horizontal cup and only the object (not the
    wrist) has to fit under the compartment's top; it is carried in level just clear of the floor,
    lowered until it touches, released, and the cup backs out the way it came."""
    import mujoco

    from anomalygen.robot.ik import quat_z_to

    drv = ep.driver
    s0 = drv.steps
    lo, hi, out = _compartment(ep, region)
    centre = (lo + hi) / 2
    laid = ""
    if too_tall_to_go_in(ep, obj, depth_inside(ep, lo, hi, out, obj)):  # lay it on its side first
        k = int(np.argmax(np.abs(out[:2])))
        spot = centre + out * (abs(hi[k] - lo[k]) / 2 + LAY_DOWN_OUT)
        if not lay_on_side(ep, obj, spot, out, lambda: grasp(ep, obj).success):
            return SkillOutcome(False, drv.steps - s0, f"{obj} is too tall for {region}'s depth and was not "
                                                       "laid on its side and taken again")
        laid = "laid on its side, "
    down = quat_z_to(np.array([0.0, 0.0, -1.0]))
    across = 0.0 if abs(out[0]) > abs(out[1]) else np.pi / 2
    turn = (across + np.pi / 2 - long_axis_yaw(ep, obj) + np.pi / 2) % np.pi - np.pi / 2
    level = _yawed(down, turn)
    axis = np.cross(np.array([0.0, 0.0, 1.0]), out)  # tipping about it turns 'down' into 'in' (-out)
    tip = np.array([np.cos(np.pi / 4), *(np.sin(np.pi / 4) * axis)])
    side = np.zeros(4)
    mujoco.mju_mulQuat(side, tip, level)
    # tip over in free space, high in front of the door
    front_hi = np.array([*(centre[:2] + out[:2] * 0.45), max(drv.site[2], hi[2] + 0.2)])
    drv.goto(np.array([*drv.site[:2], front_hi[2]]), down, max_steps=150)
    if not drv.place_base_near(front_hi, side=out, reach_poses=[(front_hi, side)]):
        return SkillOutcome(False, drv.steps - s0, f"no base pose in front of {region}'s open door")
    drv.goto(front_hi, level, max_steps=200)
    for f in np.linspace(0.25, 1.0, 4):
        q = np.zeros(4)
        mujoco.mju_mulQuat(q, np.array([np.cos(f * np.pi / 4), *(np.sin(f * np.pi / 4) * axis)]), level)
        drv.goto(front_hi, q, max_steps=40)
    turn_until_there(ep, side)
    let_swing_die(ep, obj)
    olo, ohi = drv.aabb(obj)
    below = drv.site[2] - olo[2]
    off = (olo[:2] + ohi[:2]) / 2 - drv.site[:2]  # the object lies ahead of the cup
    z = floor + below + ENTER_CLEARANCE
    inside = np.array([*(centre[:2] - off), z])
    front = inside + out * (float(np.dot(hi - lo, np.abs(out))) / 2 + 0.2)
    ok = _enter_and_set_down(ep, obj, front, inside, side, out, out * 0.01, release_after)
    if ok is None:
        return SkillOutcome(False, drv.steps - s0, f"no base pose that reaches into {region} sideways")
    return SkillOutcome(ok, drv.steps - s0, f"{obj} {laid}{'slid into' if ok else 'not fully into'} {region} "
                                               "through its door, cup pointing in")


MAX_SET_DOWN_CORRECTION = 0.15  # m: a set-down that missed its spot by more is not aimed short again
SQUARE_RATIO = 1.3  # an object whose footprint is less elongated than this is not turned before a set-down
