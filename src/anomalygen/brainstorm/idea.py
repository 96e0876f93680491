"""The structured core of a brainstormed scenario, and its conversion into a TaskProposal.

Agents (offline or LLM) think in *ideas*: a hazard class grounded in catalogue objects, a place, a
room and a person at risk. Keeping that structure separate from the wording lets recombination work
on meaning (borrow a location, a mechanism, a person) and lets every proposal be checked against
the knowledge base before any text is written.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from anomalygen.knowledge import KnowledgeBase
from anomalygen.rng import stable_hash
from anomalygen.schema import (
    DOOR,
    ArticulationUse,
    AuxiliaryItem,
    BrainstormMode,
    Engine,
    GroundingMatch,
    HazardCategory,
    Placement,
    Provenance,
    Scenario,
    TaskProposal,
)

#: Aspects an agent can borrow from another agent's proposal in rounds >= 2.
ASPECTS = ("mechanism", "location", "co_objects", "person_at_risk")


@dataclass(frozen=True)
class Idea:
    class_id: str
    target: str
    hazard: str
    placement: Placement
    room: str
    person: str
    container: str | None = None
    support: str | None = None
    co_objects: tuple[str, ...] = ()
    agent: str | None = None
    agent_index: int = 0
    round: int = 1
    builds_on: tuple[str, ...] = ()
    borrowed: tuple[str, ...] = ()

    def key(self) -> tuple:
        """What makes two ideas the same scenario (texts aside): the mechanism, the object at fault, its
        place and the room. The person at risk does not: the same open fridge told for a teenager
        rather than a parent is the same scene for the robot, and a benchmark would count it twice."""
        return (self.class_id, self.hazard, self.placement, self.room)


@dataclass
class Texts:
    name: str
    explanation: str
    description: str
    solution: str
    success_condition: str
    extra: dict[str, str] = field(default_factory=dict)


def task_id(index: int, text: str) -> str:
    """``t0001-3fa2c1d9``: a counter, unique within a tasks file, and 8 hex digits of a hash of the
    task's text. Why not a slug of the text: the id names the scene folder and every artefact of the
    task, and none of them may carry the task's words to the robot. The hash tells two runs' task
    0001 apart (a rebuilt tasks file never reuses an old task's folder); the name stays in tasks.jsonl.
    """
    return f"t{index:04d}-{stable_hash('task', text) & 0xFFFFFFFF:08x}"


def articulations_for(idea: Idea, kb: KnowledgeBase) -> list[ArticulationUse]:
    """Articulated parts the task involves: the class's own one, and a container door the fix opens."""
    hc = kb.hazard_classes[idea.class_id]
    out: list[ArticulationUse] = []
    if hc.articulation is not None:
        obj = object_of(idea, hc, hc.articulation.variable)
        part = kb.articulation_part(hc, obj)
        if part:
            out.append(
                ArticulationUse(
                    object=obj,
                    part=part,
                    function=hc.articulation.function,
                    initial_state=hc.articulation.initial_state,
                    target_state=hc.articulation.target_state,
                )
            )
    if idea.container and any(s.action == "open_joint" and s.args.get("object") == "$container" for s in hc.recipe):
        part = next((s.args["label"] for s in hc.recipe if s.action == "open_joint"), DOOR)
        out.append(
            ArticulationUse(
                object=idea.container,
                part=part,
                function="opened to put the item inside, then shut again",
                initial_state="closed",
                target_state="closed",
            )
        )
    return out


def object_of(idea: Idea, hc, variable: str) -> str:
    """The catalogue object that plays ``variable`` in an idea: the hazard, the target, or the
    co-object drawn for it (co-objects start with one per other precondition variable, in order)."""
    if variable == hc.hazard_variable:
        return idea.hazard
    others = [v for v in hc.variable_names() if v != hc.hazard_variable]
    if variable in others and others.index(variable) < len(idea.co_objects) and variable != "$target":
        return idea.co_objects[others.index(variable)]
    return idea.target


def scene_states(idea: Idea, kb: KnowledgeBase) -> dict[str, list[str]]:
    """The instance states the class needs (a sink holding water), by catalogue name."""
    from anomalygen.knowledge.mechanisms import load_mechanisms, setup_states

    hc = kb.hazard_classes[idea.class_id]
    out: dict[str, list[str]] = {}
    for var, states in setup_states(load_mechanisms(), hc).items():
        out.setdefault(object_of(idea, hc, var), []).extend(states)
    return out


def auxiliary_items(idea: Idea, kb: KnowledgeBase) -> list[AuxiliaryItem]:
    items: list[AuxiliaryItem] = []
    seen = {idea.target}

    def add(name: str | None, purpose: str) -> None:
        if name and name not in seen:
            seen.add(name)
            items.append(AuxiliaryItem(name=name, description=kb.objects[name].description, purpose=purpose))

    add(idea.hazard, "the hazard itself")
    add(idea.container, "where the robot puts the item away")
    add(idea.support, "the surface the item is moved onto")
    for co in idea.co_objects:
        add(co, "part of the everyday setting")
    return items


def to_proposal(
    idea: Idea, texts: Texts, index: int, kb: KnowledgeBase, *, engine: Engine, mode: BrainstormMode, seed: int | None, model: str | None = None
) -> TaskProposal:
    """A knowledge-base idea as a proposal: its class gives the category, the states, the parts and the
    auxiliary objects."""
    hc = kb.hazard_classes[idea.class_id]
    return build_proposal(
        idea,
        texts,
        id=task_id(index, texts.name),
        category=hc.category,
        states=scene_states(idea, kb),
        auxiliary_items=auxiliary_items(idea, kb),
        articulations=articulations_for(idea, kb),
        engine=engine,
        mode=mode,
        seed=seed,
        model=model,
    )


def build_proposal(
    idea: Idea,
    texts: Texts,
    *,
    id: str,
    category: HazardCategory,
    auxiliary_items: list[AuxiliaryItem],
    articulations: list[ArticulationUse],
    engine: Engine,
    mode: BrainstormMode,
    seed: int | None,
    model: str | None = None,
    states: dict[str, list[str]] | None = None,
    hazard_other: str | None = None,
    grounding: list[GroundingMatch] | None = None,
) -> TaskProposal:
    """The one place a TaskProposal is put together from an idea, its texts and what the engine worked
    out around them (category, states, parts, auxiliary objects; for the LLM engine also the grounding
    of the model's names). Raises pydantic's ValidationError when a piece does not fit the schema."""
    return TaskProposal(
        id=id,
        name=texts.name,
        explanation=texts.explanation,
        description=texts.description,
        category=category,
        hazard_class=idea.class_id,
        hazard_other=hazard_other,
        target_asset=idea.target,
        scenario=Scenario(
            hazard_object=idea.hazard,
            room=idea.room,
            placement=idea.placement,
            person_at_risk=idea.person,
            container=idea.container,
            co_objects=list(idea.co_objects),
            states=states or {},
        ),
        auxiliary_items=auxiliary_items,
        articulations=articulations,
        solution=texts.solution,
        success_condition=texts.success_condition,
        provenance=Provenance(
            engine=engine,
            mode=mode,
            agent_role=idea.agent,
            round=idea.round,
            builds_on=list(idea.builds_on),
            borrowed=list(idea.borrowed),
            seed=seed,
            model=model,
        ),
        grounding=grounding or [],
    )


def secondary_variables(hc) -> list[str]:
    """Precondition variables other than the hazard's (e.g. the fume source of ventilate_room): the
    objects an idea needs besides the one at fault."""
    return [v for v in hc.variable_names() if v != hc.hazard_variable]
