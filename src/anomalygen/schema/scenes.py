"""Stage 2 (build): the scene, its hidden answer key (truth.json) and the scene graph detection sees.

What each joint label means (closure, enclosing, switch) and when a joint counts as closed or off
is the table in ``part_labels.py``; ``JointState`` asks it. How high a child reaches is defined here.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any, Literal

from pydantic import Field

import anomalygen.schema.part_labels as part_labels
from anomalygen.schema.base import Artefact, Quat, Strict, Vec3
from anomalygen.schema.part_labels import CLOSED_TOL, ENCLOSED_TOL
from anomalygen.schema.vocabulary import AssetSource, ObjectRole, PredicateCall


class AssetRef(Artefact):
    """A reproducible pointer into the asset catalogue: enough to rebuild the exact asset."""

    asset_id: str
    category: str
    source: AssetSource = AssetSource.PROCEDURAL
    seed: int | None = None
    params: dict[str, Any] = Field(default_factory=dict)
    path: str | None = Field(None, description="file path for imported assets")
    package: str | None = Field(None, description="installed package a real (packaged) model comes from")
    licence: str | None = Field(None, description="SPDX licence of a packaged model's files")


CHILD_REACH = 1.0  # m: the highest a small child reaches (``child_reachable``, the detectors' checks)
# Property of a container whose shut door or lid latches (a safe's lock, a medicine cabinet's catch). The
# simulator models no latch mechanism, so the knowledge base declares it per object; only a shut
# latching container keeps a child out of something low (a plain cupboard door a toddler opens).
LATCHING_PROPERTY = "lockable"


def within_child_reach(bottom_m: float, shut_in_latched: bool) -> bool:
    """A small child can get at an object whose bottom is at most ``CHILD_REACH`` up, unless it is shut
    inside a closed latching container. One rule for the scene graph and every prediction of it."""
    return bottom_m <= CHILD_REACH and not shut_in_latched


class JointState(Artefact):
    name: str
    label: str = Field(description="semantic label: door, drawer, lid, knob, handle, button, blade, wheel, ...")
    type: Literal["hinge", "slide", "ball", "free"] = "hinge"
    value: float
    range: tuple[float, float]
    closed_value: float = Field(description="the safe/closed value of this joint")

    @property
    def open_fraction(self) -> float:
        """0 when at the closed value, 1 at the far end of the range."""
        return self.open_fraction_at(self.value)

    def open_fraction_at(self, value: float) -> float:
        """``open_fraction`` if the joint stood at ``value`` (a live simulation reading)."""
        lo, hi = self.range
        far = hi if abs(hi - self.closed_value) >= abs(lo - self.closed_value) else lo
        span = abs(far - self.closed_value)
        return 0.0 if span == 0 else min(1.0, abs(value - self.closed_value) / span)

    @property
    def encloses(self) -> bool:
        """A door, drawer, lid or flap: shut, what is behind it is out of reach."""
        return part_labels.encloses(self.label)

    @property
    def is_switch(self) -> bool:
        """An on/off control: its closed value is off."""
        return part_labels.is_switch(self.label)

    def is_closed(self, tol: float = CLOSED_TOL, value: float | None = None) -> bool:
        """At most ``tol`` of its travel away from closed (at ``value`` if given, else its own)."""
        return self.open_fraction_at(self.value if value is None else value) <= tol

    def is_off(self, tol: float = CLOSED_TOL, value: float | None = None) -> bool:
        """A switch's word for closed: at most ``tol`` of its travel from off, its closed value."""
        return self.is_closed(tol, value)


def shut_by(closers: Iterable[tuple[JointState, float]]) -> bool:
    """A space is shut when something shuts it and every joint that does is within ``ENCLOSED_TOL`` of
    closed at its value (joint, value). One rule for the scene graph's cavities (a child kept out) and
    the ``near`` predicate's walls (a chemical kept apart from food)."""
    closers = list(closers)
    return bool(closers) and all(js.is_closed(ENCLOSED_TOL, float(v)) for js, v in closers)


class PlacedCavity(Strict):
    """A declared interior of a placed object, as a box in the frame of the body it moves with.

    Why recorded: "inside" means inside a container's declared cavity, not inside its bounding box (a
    knife under a table is not in the table). A drawer's bin moves with the drawer body, a cupboard's
    space with the cabinet; the scene graph turns these boxes into world boxes from live body poses.
    """

    name: str
    body: str = Field(description="the simulator body the cavity moves with, e.g. 'cabinet_0/drawer_0_0'")
    center: Vec3 = Field(description="box centre in that body's frame, metres")
    half_extents: Vec3 = Field(description="box half sizes along that body's axes, metres")
    opening: str = Field("top", description="top | front")
    joint: str | None = Field(None, description="the scene joint that closes it (None: always open)")


class PlacedObject(Artefact):
    name: str = Field(description="unique instance name in the scene, e.g. 'knife_0'")
    asset: AssetRef
    role: ObjectRole
    size: float = Field(gt=0, description="largest dimension in metres")
    pos: Vec3
    quat: Quat = Field(default_factory=lambda: [1.0, 0.0, 0.0, 0.0])
    support: str = Field("floor", description="floor, wall (a window mounted in a wall), or '<instance>' / '<instance>:<surface>' it rests on")
    inside: str | None = Field(None, description="instance it is contained in, if any")
    joint_states: list[JointState] = Field(default_factory=list)
    fixed: bool = Field(False, description="welded to the world (furniture) rather than free")
    states: list[str] = Field(
        default_factory=list, description="instance states the builder set up: contains_water, wet, lit, ..."
    )
    cavities: list[PlacedCavity] | None = Field(
        None, description="declared interiors ([]: nothing can be inside it; None: a scene built before they were recorded)"
    )
    called: str | None = Field(
        None, description="what the object is, in the user's words, when its shape is a proxy of its kind "
        "(a bottle of 'oven cleaner' built from the cleaning spray's shape); None: its category says what it is",
    )


class ValidationCheck(Strict):
    name: str
    passed: bool
    value: float | None = None
    limit: float | None = None
    detail: str = ""


class ValidationReport(Strict):
    ok: bool
    checks: list[ValidationCheck] = Field(default_factory=list)
    repairs: int = 0
    reason: str = Field("", description="one line when not ok")


class SceneSpec(Artefact):
    scene_id: str
    task_id: str
    room: str
    seed: int
    objects: list[PlacedObject]
    robot_base: Vec3 = Field(default_factory=lambda: [0.0, 0.0, 0.0], description="x, y, yaw of the mobile base")
    bindings: dict[str, str] = Field(default_factory=dict, description="role variable -> instance, e.g. $hazard -> pill_0")
    validation: ValidationReport | None = None
    files: dict[str, str] = Field(default_factory=dict, description="logical name -> path relative to the scene folder")


class ManifestHazard(Strict):
    """A hazard the builder put in the scene, bound to instances (the answer key for one hazard)."""

    hazard_class: str
    source: Literal["intended", "incidental"] | None = Field(
        None,
        description="intended: what the builder set out to build (its bindings and class), confirmed on the "
        "settled scene; incidental: found on the settled scene by the knowledge base's matcher; None: an "
        "old manifest that did not say",
    )
    object: str = Field(description="instance name of the object at fault")
    category: str
    severity: float = Field(ge=0, le=1)
    variable: str = Field(description="the class variable bound to the object at fault, e.g. $hazard")
    bindings: dict[str, str] = Field(default_factory=dict, description="the builder's role bindings")
    success: list[PredicateCall] = Field(
        default_factory=list,
        description="the class's success predicates over the object at fault ('*' where the fix may choose, e.g. any container)",
    )
    also_fires: list[str] = Field(
        default_factory=list,
        description="other classes that hold for the same object on the settled scene (a bleach bottle beside the "
        "crib is also within a child's reach): naming one of them is a true claim about this hazard, not a false one",
    )


class NearMiss(Strict):
    """A hazard-class object the builder placed in a safe state (acting on it is unnecessary)."""

    object: str
    category: str
    looks_like: str = Field(description="the hazard class it resembles")
    why_safe: str
    kind: Literal["object", "borderline", "state"] | None = Field(
        None,
        description="object: a hazard-class object nowhere near any threshold; borderline: placed just "
        "outside a class's threshold (just-inside ones are hazards); state: a part left in its safe state "
        "(a knob at off, a door ajar a few degrees); None: an old manifest",
    )


class HazardManifest(Artefact):
    """``scenes/<task>/truth.json``: every hazard in the scene. Hidden from detect, plan and learn."""

    scene_id: str
    task_id: str
    hazards: list[ManifestHazard] = Field(default_factory=list)
    near_misses: list[NearMiss] = Field(default_factory=list)


class GraphObject(Strict):
    """What the robot perceives of one object. Never carries task or hazard names."""

    name: str
    category: str
    called: str | None = Field(None, description="what it is called, as its label reads, when its category is a proxy shape")
    properties: list[str] = Field(default_factory=list, description="sharp, choking_size, toxic, medication, ...")
    position: Vec3
    size: Vec3 = Field(description="axis-aligned extents in metres")
    height_above_floor: float
    on_floor: bool
    distance_to_edge: float | None = Field(None, description="to the edge of the surface it rests on")
    child_reachable: bool
    joints: list[JointState] = Field(default_factory=list)
    states: list[str] = Field(
        default_factory=list,
        description="what can be seen of this instance beyond its category: contains_water, wet, lit, handle_out, face_down",
    )
    held: bool = Field(False, description="attached to the robot's suction cup: on, in and under nothing")


class Relation(Strict):
    subject: str
    predicate: Literal["on", "inside", "near", "on_floor", "under", "blocks"]
    object: str | None = None
    distance: float | None = None


class SceneGraph(Artefact):
    """The observation given to detection: objects, states and relations, and nothing about the task."""

    scene_id: str
    room: str
    objects: list[GraphObject]
    relations: list[Relation] = Field(default_factory=list)

    def get(self, name: str) -> GraphObject:
        for obj in self.objects:
            if obj.name == name:
                return obj
        raise KeyError(name)
