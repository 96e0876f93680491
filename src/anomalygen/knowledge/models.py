"""Typed records of the household-hazard knowledge base.

The knowledge base is data (JSON under ``anomalygen/data/knowledge/``); these classes are its
contract. They are strict so a typo in a data file fails loudly at load time instead of silently
weakening a hazard rule that detection, planning and evaluation all rely on.
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from anomalygen.schema import HazardCategory, Placement, PredicateCall, ScalarArg

DATA_DIR = Path(__file__).resolve().parent.parent / "data"
KNOWLEDGE_DIR = DATA_DIR / "knowledge"
TARGET_VARIABLE = "$target"  # the variable bound to a task's target asset

#: Hazard-relevant object properties. Every ``has_property`` argument and every object's
#: ``properties`` entry must be one of these.
PROPERTIES: tuple[str, ...] = (
    "sharp",
    "choking_size",
    "toxic",
    "medication",
    "perishable",
    "spoiled",
    "fragile",
    "electrical",
    "hot",
    "heavy",
    "flammable",
    "cable",
    "litter",
    "container",
    "furniture",
    "appliance",
    "soft",
    "heat_source",  # makes heat or a flame when on: a burner, heater, iron, candle, toaster
    "combustible",  # catches fire from a heat source: towels, blankets, curtains, paper
    "food",  # something people eat or drink (chemicals must not be stored among it)
    "water_source",  # holds or gives water: a sink, a bathtub
    "lockable",
)

#: Properties that make an object part of *some* hazard; objects with none of them are safe clutter.
HAZARD_PROPERTIES: frozenset[str] = frozenset(
    {"sharp", "choking_size", "toxic", "medication", "perishable", "spoiled", "fragile", "hot", "heavy", "flammable", "cable", "litter"}
)

#: Instance states a scene records per object (``GraphObject.states``, read by ``has_state``): what the
#: object's category cannot say. Water in a sink is set up by the builder; a pose-dependent state
#: (a pan's handle out over the edge, an iron face down) is read from the settled simulation.
STATES: tuple[str, ...] = ("contains_water", "wet", "on", "lit", "handle_out", "face_down")

#: Support surfaces and their typical top heights (metres). The scene builder uses these heights; the
#: predicates' height thresholds (0.55 m "low", 0.6 m "raised", 1.0 m "child reach") rely on them.
SUPPORT_HEIGHTS: dict[str, tuple[float, float]] = {
    "floor": (0.0, 0.0),
    "low_table": (0.35, 0.5),
    "table": (0.7, 0.8),
    "counter": (0.85, 0.95),
    "shelf": (1.2, 1.6),
}

ROOMS: tuple[str, ...] = (
    "kitchen",
    "living_room",
    "bedroom",
    "bathroom",
    "hallway",
    "office",
    "laundry_room",
    "nursery",
)

RecipeAction = Literal[
    "pick",
    "place_inside",
    "place_on",
    "open_joint",
    "close_joint",
    "switch_off",
    "move_away_from_edge",
    "push_to",
    "close_lid",
    "open_lid",
    "take_out_of",
    "move_away",
    "take_off",
    "rotate_inward",
    "stand_upright",
]

#: Arguments each recipe action takes (all values are role variables or literal labels).
RECIPE_ARGS: dict[str, tuple[str, ...]] = {
    "pick": ("object",),
    "place_inside": ("object", "container"),
    "place_on": ("object", "support"),
    "open_joint": ("object", "label", "fraction"),  # fraction: how far to open (default: most of the way)
    "close_joint": ("object", "label"),
    "switch_off": ("object", "label"),
    "move_away_from_edge": ("object",),
    "push_to": ("object", "support"),  # slide over the floor until it stands beside the support
    "close_lid": ("object",),  # every lid or flap of a portable container
    "open_lid": ("object",),
    "take_out_of": ("object", "container"),  # lift it out (through an opened door) and keep holding it
    "move_away": ("object", "from", "distance"),  # carry or slide it at least `distance` m from `from`
    "take_off": ("object", "support"),  # lift it off what it lies on (a hob, a stair) onto a safe support
    "rotate_inward": ("object",),  # turn a pan's handle back over the hob or counter
    "stand_upright": ("object",),  # stand an iron on its heel instead of its hot soleplate
}


class KBModel(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class RecipeStep(KBModel):
    """One sub-task type of a fix, e.g. ``place_inside(object=$hazard, container=$container)``."""

    action: RecipeAction
    args: dict[str, str] = Field(default_factory=dict)
    method: Literal["primitive", "sac"] = Field(
        "primitive",
        description="how the offline planner executes the step: a motion-planned primitive, or SAC for a "
        "contact-rich part motion the package ships a warm-start policy for (data/policies/<action>.zip)",
    )

    def __str__(self) -> str:
        inner = ", ".join(f"{k}={v}" for k, v in self.args.items())
        return f"{self.action}({inner})"


class ArticulationTemplate(KBModel):
    """The articulated part a class is about and the state a scenario starts in (e.g. fridge door open)."""

    variable: str = Field(description="role variable of the articulated object, e.g. $target")
    part: str = Field(description="joint label: door, drawer, lid, knob, window, ...; alternatives 'a|b' (the object's own label is used)")
    initial_state: Literal["open", "closed", "on", "off", "other"]
    target_state: Literal["open", "closed", "on", "off", "other"]
    function: str = ""


class Composed(KBModel):
    """What a class is made of (``knowledge/mechanisms.py``): the hazard's mechanism and its fragments."""

    mechanism: str = Field(description="mechanism id: the danger, e.g. ignition_near_combustible")
    kind: str = Field(description="what the object at fault is, e.g. combustible")
    place: str = Field(description="where it is or what it is on, in or near, e.g. near_source")
    fix: str = Field(description="the fix's id, e.g. off_and_clear")
    condition: str | None = Field(None, description="its dangerous state, e.g. switched_on")
    legacy: bool = Field(False, description="a hand-written class this composition equals")


class HazardClass(KBModel):
    """One kind of household anomaly: how to see it in a scene graph, how to fix it, how to check the fix."""

    id: str
    name: str
    category: HazardCategory
    paper_class: bool = Field(description="one of the paper's 11 classes")
    at_risk: str = Field(description="who is in danger, in a phrase")
    people: list[str] = Field(default_factory=list, description="concrete people at risk, for scenario texts")
    why: str = Field(description="why it is dangerous or unhygienic, one or two sentences")
    why_by: dict[str, str] = Field(
        default_factory=dict,
        description="the reason for objects of a category or with a property (keys) where ``why`` does not fit "
                    "them all: a needle is not knocked onto a foot, a paper ball smothers nobody")
    severity: float = Field(ge=0, le=1, description="ranking weight; resolves overlaps between classes")
    variables: dict[str, str] = Field(description="role variable -> what it is bound to")
    hazard_variable: str = Field("$hazard", description="variable bound to Scenario.hazard_object (what the fix acts on)")
    preconditions: list[PredicateCall]
    recipe: list[RecipeStep]
    success: list[PredicateCall]
    placements: list[Placement] = Field(description="scenario placements under which the class can be set up "
                                        "(the data files write them as compact words: 'counter_edge', 'near:{other}')")
    default_containers: list[str] = Field(default_factory=list)
    default_supports: list[str] = Field(default_factory=list, description="catalogue names for $support (place_on)")
    hazard_objects: list[str] = Field(
        default_factory=list,
        description="curated catalogue names for the hazard variable; empty = every object meeting its intrinsic preconditions",
    )
    not_drawn: list[str] = Field(
        default_factory=list,
        description="hazard objects brainstorming does not draw yet; a user's line, the truth and the detector hold them",
    )
    undrawn_because: str | None = Field(
        None, description="why brainstorming does not draw this class yet (None: it does); users' lines still compose it")
    target_assets: list[str] = Field(description="target categories a proposal of this class may name")
    rooms: list[str] = Field(default_factory=list)
    articulation: ArticulationTemplate | None = None
    mechanism: str = Field("", description="the hazard mechanism in a short phrase (borrowed in brainstorming)")
    solution: str = Field("", description="the fix in words, with {hazard}/{container}/{support} slots")
    success_text: str = Field("", description="the safe end state in words, same slots")
    composition: Composed | None = Field(None, description="the mechanism and fragments it is composed of")

    @property
    def about_target(self) -> bool:
        """The task's target is the object at fault (a door left open, an oven left on): the state is
        on the target itself, so the object a task names at fault must be its target."""
        return self.hazard_variable == TARGET_VARIABLE

    def variable_names(self) -> list[str]:
        """Variables in first-use order across preconditions (the order match_class binds them)."""
        return _variables_in(call.args for call in self.preconditions)

    def recipe_variable_names(self) -> list[str]:
        """Variables the recipe's steps refer to, in first-use order (what a fix must bind)."""
        return _variables_in(step.args for step in self.recipe)

    def why_for(self, category: str, properties) -> str:
        """The reason a task about ``category`` gives: its own (``why_by``, by category, then by its first
        property listed there), else the class's."""
        if category in self.why_by:
            return self.why_by[category]
        return next((self.why_by[p] for p in self.why_by if p in properties), self.why)


def _variables_in(arg_dicts) -> list[str]:
    """``$variables`` among the values of ``arg_dicts``, each once, in first-use order."""
    seen: list[str] = []
    for args in arg_dicts:
        for value in args.values():
            if isinstance(value, str) and value.startswith("$") and value not in seen:
                seen.append(value)
    return seen


class PartInfo(KBModel):
    label: str = Field(description="joint label as in JointState.label: door, drawer, lid, knob, ...")
    safe_state: Literal["open", "closed", "on", "off", "any"]
    joint_type: Literal["hinge", "slide"]


class ObjectInfo(KBModel):
    name: str
    kind: Literal["target", "household"]
    description: str = ""
    properties: list[str] = Field(default_factory=list)
    size_range: tuple[float, float] = Field(description="largest dimension, metres (min, max)")
    rooms: list[str] = Field(default_factory=list)
    supports: list[str] = Field(default_factory=list, description="surfaces it usually rests on")
    containers: list[str] = Field(default_factory=list, description="catalogue names it can be stored in")
    parts: list[PartInfo] = Field(default_factory=list)
    states: list[str] = Field(default_factory=list, description="states every instance shows (a candle's flame: lit)")

    def has(self, prop: str) -> bool:
        return prop in self.properties

    def part(self, label: str) -> PartInfo | None:
        return next((p for p in self.parts if p.label == label), None)


class RoleProfile(KBModel):
    """A household role for brainstorming agents, with weighted interests (weights are relative)."""

    id: str
    name: str
    description: str
    perspective: str = Field(description="how this role looks at a home, used in prompts and texts")
    class_interests: dict[str, float] = Field(default_factory=dict)
    object_interests: dict[str, float] = Field(default_factory=dict)
    room_interests: dict[str, float] = Field(default_factory=dict)


class PredicateSpec(KBModel):
    """Documentation of one predicate: its arguments and meaning (used by docs and consistency tests)."""

    name: str
    args: dict[str, str]
    meaning: str


ArgValue = ScalarArg
