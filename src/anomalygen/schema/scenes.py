"""Stage 2 (build): the scene, its hidden answer key (truth.json) and the scene graph detection sees.

The closure concepts (which joint labels shut something, when a joint counts as closed, how high a
child reaches) are defined once here, for the builder, the scene graph, the predicates, the planners
and the skills.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import Field

from anomalygen.schema.base import Artefact, Quat, Strict, Vec3
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


# One definition of the closure concepts, shared by the scene builder, the scene graph, the
# predicates, the planners and the skills.
CLOSURE_LABELS = ("door", "drawer", "lid", "window", "sash")  # joint labels of parts that shut something
ENCLOSING_LABELS = ("door", "drawer", "lid")  # closures behind which an object is out of reach
SWINGING_CLOSURES = ("door", "lid", "window", "sash")  # closures on a hinge: they sweep out when open
CLOSED_TOL = 0.05  # open fraction at or below which a joint counts as closed (``joint_closed``'s default)
CHILD_REACH = 1.0  # m: the highest a small child reaches (``child_reachable``, the detectors' checks)


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
        """A door, drawer or lid: shut, what is behind it is out of reach."""
        return any(lbl in self.label for lbl in ENCLOSING_LABELS)

    def is_closed(self, tol: float = CLOSED_TOL, value: float | None = None) -> bool:
        """At most ``tol`` of its travel away from closed (at ``value`` if given, else its own)."""
        return self.open_fraction_at(self.value if value is None else value) <= tol


class PlacedObject(Artefact):
    name: str = Field(description="unique instance name in the scene, e.g. 'knife_0'")
    asset: AssetRef
    role: ObjectRole
    size: float = Field(gt=0, description="largest dimension in metres")
    pos: Vec3
    quat: Quat = Field(default_factory=lambda: [1.0, 0.0, 0.0, 0.0])
    support: str = Field("floor", description="floor, or '<instance>' / '<instance>:<surface>' it rests on")
    inside: str | None = Field(None, description="instance it is contained in, if any")
    joint_states: list[JointState] = Field(default_factory=list)
    fixed: bool = Field(False, description="welded to the world (furniture) rather than free")


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
    object: str = Field(description="instance name of the object at fault")
    category: str
    severity: float = Field(ge=0, le=1)
    variable: str = Field(description="the class variable bound to the object at fault, e.g. $hazard")
    bindings: dict[str, str] = Field(default_factory=dict, description="the builder's role bindings")
    success: list[PredicateCall] = Field(
        default_factory=list,
        description="the class's success predicates over the object at fault ('*' where the fix may choose, e.g. any container)",
    )


class NearMiss(Strict):
    """A hazard-class object the builder placed in a safe state (acting on it is unnecessary)."""

    object: str
    category: str
    looks_like: str = Field(description="the hazard class it resembles")
    why_safe: str


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
    properties: list[str] = Field(default_factory=list, description="sharp, choking_size, toxic, medication, ...")
    position: Vec3
    size: Vec3 = Field(description="axis-aligned extents in metres")
    height_above_floor: float
    on_floor: bool
    distance_to_edge: float | None = Field(None, description="to the edge of the surface it rests on")
    child_reachable: bool
    joints: list[JointState] = Field(default_factory=list)


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
