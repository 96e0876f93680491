"""Placement: proposals in a unit cube, then a solver for support, non-overlap and reach.

As in the paper, task-relevant objects are proposed at (x, y, z) inside the cube (0..1)^3 and
unrelated clutter outside it. The cube is mapped onto the floor area in front of the robot's home
(``REGION_ORIGIN`` .. + ``REGION_SIZE``). The solver then snaps each proposal onto its support (the
floor, a support's top surface, a container's cavity, an edge band for ``*_edge`` placements),
rejects proposals whose footprints overlap already placed objects (oriented boxes in the plane plus a
height test), checks that some free base pose has the hazard within the arm's reach, and starts the
robot at its dock, the same pose in every scene. MuJoCo contacts re-check the result after compiling (build.py), so
this solver only has to be conservative.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from anomalygen.errors import ItemFailed
from anomalygen.robot.agent import Agent
from anomalygen.scene.furniture import Support
from anomalygen.scene.walls import WALL_GAP, WALL_X, WALL_Y, mount_height
from anomalygen.schema import ObjectRole, ValidationCheck
from anomalygen.world.room import ROOM_CENTER, ROOM_HALF

REGION_ORIGIN = np.array([0.8, -0.6, 0.0])  # world position of the cube corner (0, 0, 0)
REGION_SIZE = np.array([1.1, 1.2, 1.0])
DROP_GAP = 0.002  # objects start this far above their support and settle onto it
EDGE_BAND = (0.015, 0.07)  # metres from the edge for *_edge placements (KB threshold: 0.12)
WALKWAY_CLEAR = 0.42  # > the KB's 0.3 m walkway clearance, with margin
TUCK_GAP = (0.03, 0.12)  # metres from a fixture's side for an item tucked out of the walkway (KB: 0.3)
TRIES = 60
WALL_SPAN = {"back": (-1.0, WALL_Y - 0.4), "side": (0.6, WALL_X - 0.4)}  # m along each wall where mounted objects go (not in the corner)
# Clearance kept round the robot at its start pose (its shape is the agent's: BASE_RADIUS, HOME_ARM_BOXES)
BASE_CLEAR_TOP = 0.35  # m: a box whose bottom is lower than this (the base's 0.30 m top, plus 5 cm) can hit the base
BASE_CLEAR_SIDE = 0.08  # m kept between such a box and the base disc
ARM_CLEAR = 0.03  # m kept between any box and the arm's boxes at the home pose
DOCK_YAW = math.pi / 2  # rad: the docked robot faces along the room's open front (+y), not into the room


@dataclass
class Placed:
    """A planned object: what it is, where its origin goes and what holds it."""

    name: str
    catalogue: str
    role: ObjectRole
    lo: np.ndarray  # local AABB (asset frame, bottom at z = lo[2])
    hi: np.ndarray
    fixed: bool
    asset: object | None = None
    support_geom: Support | None = None
    joint_values: dict[str, float] = field(default_factory=dict)
    states: list[str] = field(default_factory=list)  # instance states the builder set up (world/states.py)
    front: np.ndarray | None = None  # local xy unit vector of the side doors/drawers open to
    pos: np.ndarray = field(default_factory=lambda: np.zeros(3))
    yaw: float = 0.0
    support: str = "floor"
    inside: str | None = None
    sweep: float = 0.0  # extra clearance in front for open doors/drawers
    # room in front that other things keep clear of, so the robot can open the shut doors/drawers
    # (a counter 2 cm in front of a cabinet's doors keeps them shut); unlike ``sweep`` the base may
    # stand in it, and it does not push the base back from the front
    swing: float = 0.0
    intent: object = None  # what the judgement mix meant it to be (a truth.manifest.Intent), for truth.json
    called: str | None = None  # the user's name for it when its shape is a proxy of its kind (Scenario.called)

    def world_half(self) -> np.ndarray:
        c, s = abs(math.cos(self.yaw)), abs(math.sin(self.yaw))
        h = (self.hi - self.lo) / 2
        return np.array([c * h[0] + s * h[1], s * h[0] + c * h[1], h[2]])

    def world_center(self) -> np.ndarray:
        cl = (self.hi + self.lo) / 2
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return self.pos + np.array([c * cl[0] - s * cl[1], s * cl[0] + c * cl[1], cl[2]])

    def footprint(self, *, swing: bool = False) -> tuple[np.ndarray, np.ndarray]:
        """World AABB (lo, hi) including the sweep of open doors/drawers (``swing``: and the room
        kept clear in front for opening the shut ones)."""
        center, half = self.world_center(), self.world_half()
        lo, hi = center - half, center + half
        reach = max(self.sweep, self.swing) if swing else self.sweep
        if reach > 0 and self.front is not None:
            c, s = math.cos(self.yaw), math.sin(self.yaw)
            f = np.array([c * self.front[0] - s * self.front[1], s * self.front[0] + c * self.front[1], 0.0])
            lo = np.minimum(lo, lo + f * reach)
            hi = np.maximum(hi, hi + f * reach)
        return lo, hi

    @property
    def quat(self) -> list[float]:
        return [math.cos(self.yaw / 2), 0.0, 0.0, math.sin(self.yaw / 2)]


def face_robot_yaw(front: np.ndarray | None, target_dir: np.ndarray) -> float:
    """Yaw that turns the local ``front`` direction towards ``target_dir`` (both xy)."""
    if front is None:
        return 0.0
    return math.atan2(target_dir[1], target_dir[0]) - math.atan2(front[1], front[0])


def reached_from_front(obj: Placed) -> bool:
    """A loose thing worked from its front (a space heater's dial): the builder turns that side to the
    open floor where it can, as it turns furniture to the robot."""
    return obj.front is not None and obj.asset is not None and obj.asset.front_access


def overlaps(
    a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray], margin: float = 0.02
) -> bool:
    return bool(np.all(a[0] < b[1] + margin) and np.all(b[0] < a[1] + margin))


class Layout:
    """The solver state: placed objects and the robot base."""

    def __init__(self, rng: np.random.Generator, *, relevant_in_cube: bool = True):
        self.rng = rng
        self.relevant_in_cube = relevant_in_cube
        self.items: list[Placed] = []
        self.base = np.array([0.0, 0.0, 0.0])
        #: Floor positions an engine proposed per instance (the LLM scene engine); tried first.
        self.preferred: dict[str, np.ndarray] = {}
        #: What the solver did with each preferred position, for the scene's validation report.
        self.corrections: list[ValidationCheck] = []

    # ---------------------------------------------------------------- proposals
    def propose_xy(self, relevant: bool) -> np.ndarray:
        """A proposal in the unit cube (relevant) or outside it (unrelated), mapped to the floor."""
        if relevant or not self.relevant_in_cube:
            u = self.rng.uniform(0.0, 1.0, size=2)
            return REGION_ORIGIN[:2] + u * REGION_SIZE[:2]
        for _ in range(100):
            p = ROOM_CENTER + self.rng.uniform(-1, 1, size=2) * ROOM_HALF
            u = (p - REGION_ORIGIN[:2]) / REGION_SIZE[:2]
            if not np.all((u >= 0) & (u <= 1)) and np.linalg.norm(p - self.base[:2]) > Agent.BASE_RADIUS + 0.4:
                return p
        return ROOM_CENTER + np.array([1.2, 0.0])

    # ---------------------------------------------------------------- checks
    def collides(self, obj: Placed, *, ignore: tuple[str, ...] = ()) -> bool:
        box = obj.footprint()
        if np.any(box[0][:2] < ROOM_CENTER - ROOM_HALF - 0.3) or np.any(box[1][:2] > self.walls()):
            return True  # off the floor, or into a wall
        zone = obj.footprint(swing=True)
        for other in self.items:
            if other.name in ignore or other.name == obj.name:
                continue
            if overlaps(zone, other.footprint()) or overlaps(box, other.footprint(swing=True)):
                return True
        return self._hits_base(box)

    @staticmethod
    def walls() -> np.ndarray:
        """The walls' inner faces (x of the back wall, y of the side wall): a footprint ends at them."""
        return np.array([WALL_X, WALL_Y])

    def _hits_base(self, box) -> bool:
        """Does a world AABB intrude on the robot: its base disc, or the arm's box at the home pose?"""
        if box[0][2] < BASE_CLEAR_TOP:
            closest = np.clip(self.base[:2], box[0][:2], box[1][:2])
            if float(np.linalg.norm(closest - self.base[:2])) < Agent.BASE_RADIUS + BASE_CLEAR_SIDE:
                return True
        return any(overlaps(box, arm, margin=ARM_CLEAR) for arm in self.arm_boxes())

    def arm_boxes(self) -> list[tuple[np.ndarray, np.ndarray]]:
        """World AABBs of the arm at its home pose (``Agent.HOME_ARM_BOXES``, turned with the base)."""
        c, s = math.cos(self.base[2]), math.sin(self.base[2])
        out = []
        for (x0, x1), (y0, y1), (z0, z1) in Agent.HOME_ARM_BOXES:
            xy = np.array([[self.base[0] + c * x - s * y, self.base[1] + s * x + c * y] for x in (x0, x1) for y in (y0, y1)])
            out.append((np.r_[xy.min(0), z0], np.r_[xy.max(0), z1]))
        return out

    # ---------------------------------------------------------------- placing
    def place_on_floor(
        self, obj: Placed, *, relevant: bool, face: bool = True, clear_of: list[Placed] | None = None
    ) -> None:
        """Stand ``obj`` on the floor at a proposal that overlaps nothing (furniture faces the robot).

        A preferred position is tried first; if it overlaps, the solver falls back on its own draws
        and records the move. A window or door is mounted in a wall instead (``place_on_wall``)."""
        bottom = mount_height(obj.catalogue)
        if bottom is not None and obj.fixed and obj.support_geom is None:
            self.place_on_wall(obj, bottom)
            return
        want = self.preferred.get(obj.name)
        for attempt in range(2 * TRIES):
            # a crowded cube: fall back to anywhere in the room rather than fail the scene
            xy = want.copy() if (want is not None and attempt == 0) else self.propose_xy(relevant and attempt < TRIES)
            if face and obj.front is not None:
                # furniture faces the robot, square to the room (multiples of 90 degrees)
                yaw = face_robot_yaw(obj.front, self.base[:2] - xy)
                yaw = round(yaw / (math.pi / 2)) * (math.pi / 2)
            else:
                yaw = float(self.rng.uniform(-math.pi, math.pi))
            obj.yaw = yaw
            if obj.support_geom is not None:
                z = 0.0  # built from floor level
            else:
                z = -obj.lo[2] + (0.0 if obj.fixed else DROP_GAP)
            obj.pos = np.array([xy[0], xy[1], z])
            obj.pos[:2] -= obj.world_center()[:2] - obj.pos[:2]  # centre the footprint on the proposal
            if clear_of is not None and any(
                _h_gap(obj.footprint(), f.footprint()) < WALKWAY_CLEAR for f in clear_of
            ):
                continue
            if not self.collides(obj):
                obj.support = "floor"
                self.items.append(obj)
                if want is not None:
                    self._record_preferred(obj, want, moved=attempt > 0)
                return
        raise ItemFailed(f"no free floor spot for {obj.name}")

    def place_on_wall(self, obj: Placed, bottom: float) -> str:
        """Mount ``obj`` (a window, a door) in the back or side wall, its front into the room and its
        bottom ``bottom`` above the floor; returns the wall ("back" or "side")."""
        for _ in range(TRIES):
            wall = "back" if self.rng.random() < 0.5 else "side"
            obj.yaw = face_robot_yaw(obj.front, np.array([-1.0, 0.0]) if wall == "back" else np.array([0.0, -1.0]))
            half = obj.world_half()
            lo_a, hi_a = WALL_SPAN[wall][0] + half[1 - (wall == "side")], WALL_SPAN[wall][1] - half[1 - (wall == "side")]
            if hi_a < lo_a:
                continue
            center = np.zeros(2)
            axis = 0 if wall == "back" else 1  # the wall's normal
            center[axis] = (WALL_X if wall == "back" else WALL_Y) - WALL_GAP - half[axis]
            center[1 - axis] = self.rng.uniform(lo_a, hi_a)
            obj.pos = np.array([0.0, 0.0, bottom - obj.lo[2]])
            obj.pos[:2] = center - (obj.world_center()[:2] - obj.pos[:2])
            if not self.collides(obj):
                obj.support = "floor" if bottom <= 0.0 else "wall"
                self.items.append(obj)
                want = self.preferred.get(obj.name)
                if want is not None:  # an engine's floor spot: said, not silently dropped
                    got = obj.world_center()[:2]
                    self.corrections.append(ValidationCheck(
                        name=f"position:{obj.name}", passed=True, value=round(float(np.linalg.norm(got - want)), 4),
                        detail=f"proposed at ({want[0]:.2f}, {want[1]:.2f}); a {obj.catalogue} is mounted in a wall: "
                               f"the {wall} wall at ({got[0]:.2f}, {got[1]:.2f})"))
                return wall
        raise ItemFailed(f"no free spot in a wall for {obj.name}")

    def place_beside(self, obj: Placed, fixtures: list[Placed]) -> None:
        """Stand a loose object on the floor against the side of a piece of furniture, out of the walkway.

        Why: an ordinary object the builder leaves in the open floor is, by the knowledge base's own
        rule, a tripping hazard the scene never meant to have. Falls back on a free floor spot only
        when no fixture has room beside it."""
        bodies = [f for f in fixtures if f.fixed]
        for _ in range(TRIES if bodies else 0):
            f = bodies[int(self.rng.integers(len(bodies)))]
            c, h = f.world_center(), f.world_half()  # the body itself, not its doors' sweep
            obj.yaw = float(self.rng.uniform(-math.pi, math.pi))
            axis, sign = int(self.rng.integers(2)), float(self.rng.choice([-1.0, 1.0]))
            if reached_from_front(obj):  # its controls face the open floor, away from the furniture
                obj.yaw = face_robot_yaw(obj.front, np.eye(2)[axis] * sign)
            oh = obj.world_half()
            xy = c[:2].copy()
            xy[axis] += sign * (h[axis] + oh[axis] + self.rng.uniform(*TUCK_GAP))
            xy[1 - axis] += self.rng.uniform(-1.0, 1.0) * max(h[1 - axis] - oh[1 - axis], 0.0)
            obj.pos = np.array([xy[0], xy[1], -obj.lo[2] + DROP_GAP])
            obj.pos[:2] -= obj.world_center()[:2] - obj.pos[:2]
            if not self.collides(obj):
                obj.support = "floor"
                self.items.append(obj)
                return
        self.place_on_floor(obj, relevant=True, face=False)

    def _record_preferred(self, obj: Placed, want: np.ndarray, *, moved: bool) -> None:
        got = obj.world_center()[:2]
        shift = float(np.linalg.norm(got - want))
        detail = (f"proposed at ({want[0]:.2f}, {want[1]:.2f}) overlapped another object, the robot or the walkway; "
                  f"moved to ({got[0]:.2f}, {got[1]:.2f})") if moved else f"placed at the proposed ({want[0]:.2f}, {want[1]:.2f})"
        self.corrections.append(ValidationCheck(name=f"position:{obj.name}", passed=True, value=round(shift, 4), detail=detail))

    def robot_edge(self, surface) -> tuple[int, float]:
        """(axis, sign) of the edge of a surface rectangle (world lo_xy, hi_xy, top z) that faces the
        robot's base: the side an object near the edge is reached from."""
        lo_xy, hi_xy, _ = surface
        to_base = self.base[:2] - (lo_xy + hi_xy) / 2
        axis = int(np.argmax(np.abs(to_base)))
        return axis, float(np.sign(to_base[axis]) or -1.0)

    def place_on_surface(
        self,
        obj: Placed,
        holder: Placed,
        surface: tuple[np.ndarray, np.ndarray, float],
        *,
        edge: bool = False,
        inward: float = 0.0,
        label: str | None = None,
        near_side: float | None = None,
        yaw: float | None = None,
        edge_gap: float | None = None,
    ) -> None:
        """Rest ``obj`` on a rectangle (world lo_xy, hi_xy, top z) of ``holder``.

        ``edge``: the footprint ends 1.5-7 cm from the surface edge that faces the robot (the
        knowledge base counts <= 12 cm as "near the edge"); ``edge_gap``: exactly this far from that
        edge instead (a near-miss just either side of the rule). ``inward``: keep this far from all edges
        (less when the object is too big for that). ``near_side``: the object's centre at most this
        far from the robot-facing edge, so the arm reaches it from beside the support. ``yaw``: stand
        it at this yaw (an appliance whose door faces out over the edge) instead of a random one.
        """
        lo_xy, hi_xy, top = surface
        axis, sign = self.robot_edge(surface)
        for _ in range(TRIES):
            obj.yaw = yaw if yaw is not None else float(
                self.rng.choice([0.0, math.pi / 2, math.pi, -math.pi / 2]) + self.rng.uniform(-0.15, 0.15)
            )
            half = obj.world_half()
            slack = (hi_xy - lo_xy) / 2 - half[:2]
            if np.any(slack < 0) and yaw is not None:
                raise ItemFailed(f"{obj.name} does not fit on {holder.name} at the yaw asked for")
            if np.any(slack < 0):
                obj.yaw = 0.0 if (obj.hi - obj.lo)[0] <= (obj.hi - obj.lo)[1] else math.pi / 2
                half = obj.world_half()
                slack = (hi_xy - lo_xy) / 2 - half[:2]
                if np.any(slack < -1e-6):  # square the other way: a book across a deep shelf board
                    obj.yaw = math.pi / 2 - obj.yaw
                    half = obj.world_half()
                    slack = (hi_xy - lo_xy) / 2 - half[:2]
                if np.any(slack < -1e-6):
                    raise ItemFailed(
                        f"{obj.name} ({2 * half[0]:.2f}x{2 * half[1]:.2f} m) does not fit on {holder.name}"
                    )
            room = np.where(slack - inward >= 0, slack - inward, 0.0)
            center = (lo_xy + hi_xy) / 2 + self.rng.uniform(-1, 1, size=2) * room
            bound = hi_xy[axis] if sign > 0 else lo_xy[axis]
            if edge or edge_gap is not None:
                # The robot-facing edge of the surface: the side whose outward normal points to the base.
                gap = edge_gap if edge_gap is not None else self.rng.uniform(*EDGE_BAND)
                center[axis] = bound - sign * (half[axis] + gap)
            elif near_side is not None:
                depth = abs(center[axis] - bound)
                if depth > near_side:
                    lo_d = min(near_side, half[axis] + min(inward, max(slack[axis], 0.0)))
                    center[axis] = bound - sign * self.rng.uniform(lo_d, max(lo_d, near_side))
            cl = (obj.hi + obj.lo) / 2
            c, s = math.cos(obj.yaw), math.sin(obj.yaw)
            offset = np.array([c * cl[0] - s * cl[1], s * cl[0] + c * cl[1]])
            obj.pos = np.array([center[0] - offset[0], center[1] - offset[1], top - obj.lo[2] + DROP_GAP])
            if not self.collides(obj, ignore=(holder.name,)):
                obj.support = label or holder.name
                self.items.append(obj)
                return
        raise ItemFailed(f"no free spot for {obj.name} on {holder.name}")

    def place_in_cavity(
        self, obj: Placed, holder: Placed, cavity_world: tuple[np.ndarray, np.ndarray],
        front: np.ndarray | None = None,
    ) -> None:
        """Put ``obj`` on the floor of a cavity (world AABB), centred with a little jitter.

        ``front`` (world, horizontal, out of a door's opening) keeps it in the front half: the arm
        reaches 0.33-0.36 m past a fridge's opening into its lowest compartment
        (``benchmarks/reach_into_compartment.py``), and a task must stay within what the robot can
        do, as the paper's do. The draw is the same either way, only mapped onto the front half.
        """
        lo, hi = cavity_world
        obj.yaw = holder.yaw
        half = obj.world_half()
        room = (hi[:2] - lo[:2]) / 2 - half[:2] - 0.01
        if np.any(room < 0):  # long things lie along the cavity's long side
            obj.yaw = holder.yaw + math.pi / 2
            half = obj.world_half()
            room = (hi[:2] - lo[:2]) / 2 - half[:2] - 0.01
        if np.any(room < 0) or (hi[2] - lo[2]) < 2 * half[2] + 0.01:
            raise ItemFailed(f"{obj.name} does not fit inside {holder.name}")
        jitter = self.rng.uniform(-0.5, 0.5, size=2)
        if front is not None:
            k = int(np.argmax(np.abs(front[:2])))
            jitter[k] = np.sign(front[k]) * (jitter[k] + 0.5) / 2  # [-0.5, 0.5] -> the front half
        center = (lo[:2] + hi[:2]) / 2 + jitter * room
        cl = (obj.hi + obj.lo) / 2
        c, s = math.cos(obj.yaw), math.sin(obj.yaw)
        offset = np.array([c * cl[0] - s * cl[1], s * cl[0] + c * cl[1]])
        obj.pos = np.array([center[0] - offset[0], center[1] - offset[1], lo[2] - obj.lo[2] + DROP_GAP])
        obj.support = holder.name
        obj.inside = holder.name
        self.items.append(obj)

    # ---------------------------------------------------------------- reach
    def fit_base(self, focus: Placed, holder: Placed | None = None) -> None:
        """Move the base so ``focus`` is within reach, facing it, clear of every footprint.

        The distances are the agent's reach envelope (``Agent.REACH``, robot/reach.py): loose objects
        within its ``object_band`` of the base centre (horizontally); furniture with its footprint
        (doors swept open included) within ``furniture_band``, so the arm's home pose clears it and
        the arm still reaches the door edge or handle; an object inside furniture (``holder``): the
        furniture rule, and the object within ``inside_max``. Among valid poses the one closest to the
        room's robot home (the origin) wins, so scenes look alike.
        """
        target = focus.world_center()
        if target[2] > Agent.REACH.max_height and not focus.fixed:
            raise ItemFailed(f"the robot cannot reach {focus.name} at {target[2]:.2f} m")
        inner = None
        if holder is not None and holder.fixed:
            inner, focus = target, holder
        box = focus.footprint()
        best, best_cost = None, np.inf
        lo = ROOM_CENTER - ROOM_HALF + Agent.BASE_RADIUS
        hi = ROOM_CENTER + ROOM_HALF - Agent.BASE_RADIUS
        for x in np.arange(lo[0], hi[0] + 1e-9, 0.1):
            for y in np.arange(lo[1], hi[1] + 1e-9, 0.1):
                xy = np.array([x, y])
                if focus.fixed:
                    closest = np.clip(xy, box[0][:2], box[1][:2])
                    gap = float(np.linalg.norm(closest - xy))
                    if not Agent.REACH.furniture_band[0] <= gap <= Agent.REACH.furniture_band[1]:
                        continue
                    if inner is not None and np.linalg.norm(inner[:2] - xy) > Agent.REACH.inside_max:
                        continue
                    aim = closest if inner is None else inner[:2]
                else:
                    d = float(np.linalg.norm(target[:2] - xy))
                    if not Agent.REACH.object_band[0] <= d <= Agent.REACH.object_band[1]:
                        continue
                    aim = target[:2]
                cost = float(np.linalg.norm(xy))
                if cost >= best_cost:
                    continue
                if self._base_ok(xy, aim):
                    best, best_cost = (xy, aim), cost
        if best is None:
            raise ItemFailed(f"the robot cannot reach {focus.name}: no free base pose")
        xy, aim = best
        self.base = np.array([xy[0], xy[1], math.atan2(aim[1] - xy[1], aim[0] - xy[0])])

    def _base_ok(self, xy: np.ndarray, aim: np.ndarray) -> bool:
        return self._pose_free(xy, math.atan2(aim[1] - xy[1], aim[0] - xy[0]))

    def _pose_free(self, xy: np.ndarray, yaw: float, *, swing: bool = False) -> bool:
        """Would the robot at (xy, yaw) clear every placed footprint (``swing``: and the room kept
        in front of shut doors and drawers)?"""
        old = self.base.copy()
        self.base = np.array([xy[0], xy[1], yaw])
        try:
            return not any(self._hits_base(o.footprint(swing=swing)) for o in self.items)
        finally:
            self.base = old

    def dock_pose(self) -> np.ndarray:
        """Where the robot starts (x, y, yaw): its dock at the room's home (the origin), the same in
        every scene, turned along the room's open front (``DOCK_YAW``) rather than into it.

        Why: the base used to start 0.35-0.85 m from the hazard and facing it, which told the robot
        what to look at. The dock aims at no object, so it cannot depend on which one is the hazard;
        the skills move the base to each target themselves, choosing among the poses around it the
        one nearest the dock, as the old start pose was the one nearest it. Every object was placed
        clear of the robot standing there facing into the room (yaw 0), which is used when the arm
        turned along the front would touch something."""
        if self._pose_free(np.zeros(2), DOCK_YAW, swing=True):
            return np.array([0.0, 0.0, DOCK_YAW])
        return np.zeros(3)

def _h_gap(a, b) -> float:
    gap = np.maximum(0.0, np.maximum(a[0][:2] - b[1][:2], b[0][:2] - a[1][:2]))
    return float(np.linalg.norm(gap))


def surface_world(holder: Placed, center_local, half_size) -> tuple[np.ndarray, np.ndarray, float]:
    """A holder's local surface rectangle in world coordinates (yaw multiples of 90 deg handled exactly)."""
    c, s = math.cos(holder.yaw), math.sin(holder.yaw)
    cx, cy, top = center_local
    center = holder.pos[:2] + np.array([c * cx - s * cy, s * cx + c * cy])
    hx, hy = half_size
    half = np.array([abs(c) * hx + abs(s) * hy, abs(s) * hx + abs(c) * hy])
    # a rotated rectangle's axis-aligned box is larger than the rectangle: shrink to stay on it
    if abs(math.sin(2 * holder.yaw)) > 1e-3:
        half = np.minimum(half, np.array([min(hx, hy)] * 2))
    return center - half, center + half, float(holder.pos[2] + top)
