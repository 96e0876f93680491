"""The data model: one pydantic class per artefact that crosses a stage.

Every artefact is a file in the run folder, so each class is strict (unknown fields are errors, not
silently dropped) and carries a ``schema_version`` so old runs can be detected rather than misread.
Stages depend on these classes, never on each other's internals.
"""

from __future__ import annotations

from enum import StrEnum
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError

SCHEMA_VERSION = "1"

Vec3 = Annotated[list[float], Field(min_length=3, max_length=3)]
Quat = Annotated[list[float], Field(min_length=4, max_length=4, description="w, x, y, z")]
ScalarArg = str | float | int | bool


class Artefact(BaseModel):
    """Base for every stage artefact: strict, versioned, JSON round-trippable."""

    model_config = ConfigDict(extra="forbid", validate_assignment=True, populate_by_name=True)

    schema_version: str = SCHEMA_VERSION


class Strict(BaseModel):
    """Base for nested records: strict like artefacts, without their own version field."""

    model_config = ConfigDict(extra="forbid", validate_assignment=True)


# --------------------------------------------------------------------------- vocabulary


class HazardCategory(StrEnum):
    """The paper's three top-level anomaly categories."""

    HOUSEHOLD_HAZARD = "household_hazard"
    HYGIENE = "hygiene"
    CHILD_SAFETY = "child_safety"


class AssetSource(StrEnum):
    PROCEDURAL = "procedural"
    PARTNET = "partnet"
    PACKAGED = "packaged"
    OBJAVERSE = "objaverse"


class BrainstormMode(StrEnum):
    """Ablation modes of stage 1: no roles/no rounds, roles only, full group brainstorming."""

    PLAIN = "plain"
    ROLEPLAY = "roleplay"
    BRAINSTORM = "brainstorm"


class Engine(StrEnum):
    KNOWLEDGE = "knowledge"
    LLM = "llm"


class ObjectRole(StrEnum):
    """Why an object is in a scene. Only the scene builder and evaluator see this, never detection."""

    TARGET = "target"  # the paper's target asset (one of the 44 categories)
    HAZARD = "hazard"  # the object that constitutes the hazard (may be the target itself)
    CONTAINER = "container"  # where the fix puts the hazard object
    SUPPORT = "support"  # table, counter, shelf the scene stands on
    AUXILIARY = "auxiliary"  # task-relevant extra item
    CLUTTER = "clutter"  # unrelated everyday object


class SkillMethod(StrEnum):
    PRIMITIVE = "primitive"
    SAC = "sac"
    CEM = "cem"


# --------------------------------------------------------------------------- predicates


class PredicateCall(Strict):
    """A call of a knowledge-base predicate, e.g. ``on_floor(object=$hazard)``.

    Arguments that start with ``$`` are role variables (``$hazard``, ``$target``, ``$container``)
    bound to scene object names when evaluated; the knowledge base defines the predicate names.
    """

    name: str
    args: dict[str, ScalarArg] = Field(default_factory=dict)
    negate: bool = False


class PredicateResult(Strict):
    call: PredicateCall
    holds: bool
    explanation: str = ""


# --------------------------------------------------------------------------- stage 1: proposals


class Provenance(Strict):
    """Where a proposal came from, so brainstorming can be audited and ablated."""

    engine: Engine
    mode: BrainstormMode
    agent_role: str | None = None
    round: int = Field(1, ge=1)
    builds_on: list[str] = Field(default_factory=list, description="ids of proposals this one borrows from")
    borrowed: list[str] = Field(default_factory=list, description="which aspects were borrowed, e.g. 'location'")
    seed: int | None = None
    model: str | None = None


class AuxiliaryItem(Strict):
    name: str = Field(description="catalogue name of the object, e.g. 'pill_bottle'")
    description: str = ""
    purpose: str = Field("", description="why the object is in the scene")
    relevant: bool = True


class ArticulationUse(Strict):
    """An articulated part the task involves and the state it starts in."""

    object: str = Field(description="catalogue name of the articulated object")
    part: str = Field(description="semantic label of the part: door, drawer, lid, knob, ...")
    function: str = ""
    initial_state: Literal["open", "closed", "on", "off", "other"] = "open"
    target_state: Literal["open", "closed", "on", "off", "other"] = "closed"


class Scenario(Strict):
    """The grounded, machine-readable core of a proposal; the texts are realised from it."""

    hazard_object: str = Field(description="catalogue name of the object that is the hazard")
    room: str = Field(description="kitchen, living_room, bedroom, bathroom, hallway, ...")
    placement: str = Field(description="where the hazard object is: floor, table, counter_edge, shelf, inside:<object>, ...")
    person_at_risk: str = ""
    container: str | None = Field(None, description="catalogue name of the safe destination, if the fix stores it")
    co_objects: list[str] = Field(default_factory=list, description="other catalogue objects in the story")


class GroundingMatch(Strict):
    """How one name an LLM (or a user's free text) wrote was resolved to a knowledge-base name.

    Kept in the artefact so a reader can audit every loose name: what was written, what it became,
    by which step (exact, normalised spelling, alias, Sentence-BERT retrieval, a class default, or
    dropped) and how similar the retrieved match was (1.0 for the deterministic steps).
    """

    field: str = Field(description="where the name was written, e.g. 'scenario.container'")
    written: str
    grounded: str | None = Field(None, description="the knowledge-base name; None when the name was dropped")
    method: Literal["exact", "normalised", "alias", "retrieval", "class_default", "other", "dropped"]
    similarity: float = 1.0
    alternatives: list[str] = Field(default_factory=list, description="the next retrieval candidates, best first")


class TaskProposal(Artefact):
    """One anomaly scenario (the paper's task format plus the grounding our later stages need)."""

    id: str
    name: str
    explanation: str
    description: str
    category: HazardCategory
    hazard_class: str = Field(description="id of a knowledge-base hazard class, or 'other'")
    hazard_other: str | None = Field(None, description="free text when hazard_class is 'other'")
    target_asset: str = Field(description="one of the 44 target asset categories")
    scenario: Scenario
    auxiliary_items: list[AuxiliaryItem] = Field(default_factory=list)
    articulations: list[ArticulationUse] = Field(default_factory=list)
    solution: str = Field("", description="how the hazard is resolved, in words")
    success_condition: str = Field("", description="the safe end state, in words")
    provenance: Provenance
    grounding: list[GroundingMatch] = Field(default_factory=list, description="loose names resolved to catalogue names")


# --------------------------------------------------------------------------- stage 2: scenes


class AssetRef(Artefact):
    """A reproducible pointer into the asset catalogue: enough to rebuild the exact asset."""

    asset_id: str
    category: str
    source: AssetSource = AssetSource.PROCEDURAL
    seed: int | None = None
    params: dict[str, Any] = Field(default_factory=dict)
    path: str | None = Field(None, description="file path for imported assets")


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


# --------------------------------------------------------------------------- stage 3: detection


class Hypothesis(Artefact):
    rank: int = Field(ge=1)
    problem: str
    solution: str
    target_object: str = Field(description="instance name (or category) of the object at fault")
    hazard_class: str | None = None
    score: float = 0.0
    explanation: str = ""


class Judgement(Strict):
    rank: int
    hit: bool
    method: Literal["exact", "sbert", "llm", "none"]
    similarity: float | None = None
    reason: str = ""


class Detection(Artefact):
    task_id: str
    scene_id: str
    detector: Literal["rules", "llm", "hybrid"]
    hypotheses: list[Hypothesis]
    judgements: list[Judgement] = Field(default_factory=list)
    hit_rank: int | None = Field(None, description="rank of the first hit, None for a miss")
    miss_reason: str | None = None
    error: str | None = None
    hazard_free: bool = Field(
        False, description="the scene's truth lists no hazard: left out of hit@k (it counts in the false-alarm rate)"
    )


# --------------------------------------------------------------------------- stage 4: plans and skills


class RewardTerm(Strict):
    """One composable reward term. ``kind`` selects the meaning of the other fields."""

    kind: Literal["distance", "joint", "inside", "lifted", "upright", "action_penalty"]
    weight: float = 1.0
    a: str | None = Field(None, description="object/link the term is about (instance or instance:link)")
    b: str | None = Field(None, description="other object, link or region for distance/inside")
    target: float | list[float] | None = Field(None, description="target joint value, height, or position")
    joint: str | None = None
    scale: float = 1.0


class RewardSpec(Artefact):
    mode: Literal["spec", "code"] = "spec"
    terms: list[RewardTerm] = Field(default_factory=list)
    code: str | None = Field(None, description="for mode 'code': source of compute_reward(state) -> float")


class SuccessSpec(Artefact):
    """All predicates must hold (after negation) for success."""

    predicates: list[PredicateCall] = Field(default_factory=list)


class SubTask(Artefact):
    id: str
    description: str
    method: SkillMethod
    primitive: str | None = Field(None, description="grasp, approach, release, move_to, push, pull, ...")
    params: dict[str, ScalarArg | list[float]] = Field(default_factory=dict)
    reward: RewardSpec | None = None
    success: SuccessSpec = Field(default_factory=SuccessSpec)


class Plan(Artefact):
    task_id: str
    source: Literal["ground_truth", "detected"]
    engine: Engine
    subtasks: list[SubTask]
    success: SuccessSpec
    bindings: dict[str, str] = Field(default_factory=dict)


class SubTaskResult(Strict):
    id: str
    method: SkillMethod
    success: bool
    steps: int = 0
    wall_s: float = 0.0
    detail: str = ""
    attempts: int = Field(1, ge=1, description="executions of the sub-task: retried when its check failed")


class HazardOutcome(Strict):
    """One manifest hazard after execution, as the referee judged it on the final scene graph."""

    hazard_class: str
    object: str
    resolved: bool
    detail: str = ""


class FixOutcome(Strict):
    """The hidden-truth verdict on one execution (written by the referee, never read by the robot)."""

    hazards: list[HazardOutcome] = Field(default_factory=list)
    resolved: bool = Field(description="every manifest hazard is resolved (a hazard-free scene: True)")
    new_hazards: list[str] = Field(
        default_factory=list, description="'class on object' hazards present at the end and not at the start"
    )
    interventions_on_safe: list[str] = Field(
        default_factory=list, description="near-miss objects the robot moved or whose parts it moved"
    )


class SkillResult(Artefact):
    task_id: str
    seed: int
    success: bool = Field(description="the plan's own final condition held (what the robot believes)")
    subtasks: list[SubTaskResult] = Field(default_factory=list)
    final_predicates: list[PredicateResult] = Field(default_factory=list)
    video: str | None = None
    timings: dict[str, float] = Field(default_factory=dict)
    error: str | None = None
    outcome: FixOutcome | None = Field(None, description="the referee's verdict against truth.json; None without one")


# --------------------------------------------------------------------------- run bookkeeping


class StageRecord(Strict):
    started: str | None = None
    finished: str | None = None
    wall_s: float = 0.0
    done: int = 0
    skipped: int = 0
    failed: int = 0


class LLMUsage(Strict):
    requests: int = 0
    prompt_tokens: int = 0
    completion_tokens: int = 0
    cache_hits: int = 0
    cache_misses: int = 0
    retries: int = 0
    truncated: int = Field(0, description="replies that used the whole max_tokens budget (likely cut off)")
    cost_usd: float | None = None

    def add(self, other: LLMUsage) -> None:
        for field in ("requests", "prompt_tokens", "completion_tokens", "cache_hits", "cache_misses", "retries", "truncated"):
            setattr(self, field, getattr(self, field) + getattr(other, field))
        if other.cost_usd is not None:
            self.cost_usd = (self.cost_usd or 0.0) + other.cost_usd


class RunManifest(Artefact):
    name: str
    created: str
    package_version: str
    git_commit: str | None = None
    seed: int = 0
    config: dict[str, Any] = Field(default_factory=dict, description="effective config, secrets masked")
    llm_backend: str | None = None
    llm_model: str | None = None
    stages: dict[str, StageRecord] = Field(default_factory=dict)
    llm_usage: LLMUsage = Field(default_factory=LLMUsage)


class ItemError(Artefact):
    """A per-item failure, written in place of the item's output so a batch never dies of one item."""

    item_id: str
    stage: str
    error: str


ARTEFACTS: dict[str, type[BaseModel]] = {
    cls.__name__: cls
    for cls in (
        TaskProposal,
        AssetRef,
        PlacedObject,
        JointState,
        SceneSpec,
        HazardManifest,
        SceneGraph,
        Hypothesis,
        Detection,
        SubTask,
        Plan,
        RewardSpec,
        SuccessSpec,
        SkillResult,
        RunManifest,
        ItemError,
    )
}


def format_validation_error(err: ValidationError, *, limit: int = 5) -> str:
    """One readable line per problem, naming the offending field (used in CLI errors and LLM repair)."""
    lines = []
    for e in err.errors()[:limit]:
        loc = ".".join(str(p) for p in e["loc"]) or "<root>"
        if e["type"] == "extra_forbidden":
            lines.append(f"unknown field '{loc}' is not allowed")
        else:
            lines.append(f"{loc}: {e['msg']}")
    more = len(err.errors()) - limit
    if more > 0:
        lines.append(f"... and {more} more")
    return "; ".join(lines)
