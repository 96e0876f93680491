"""The LLM detector: the paper's stage 3 — show the model the scene, ask for up to k problems and fixes.

The model sees the observation (objects, states, relations; never the task) and the knowledge base's
list of hazard classes, and answers with structured hypotheses through the LLM layer. Its reply is
untrusted: the reply schema is built per scene so ``target_object`` must name an object that is
actually in the scene and ``hazard_class`` must be a known class id; a reply that breaks either goes
back to the model with the validation error (the LLM layer's repair loop), and a scene whose replies
never validate fails alone (``LLMItemError``), never the batch.
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, create_model

from anomalygen.detect.observation import observation_text
from anomalygen.schema import Hypothesis, SceneGraph

SYSTEM_PROMPT = (
    "You are the safety sense of a household robot (a Franka arm with a suction gripper on a mobile base). "
    "You are shown what the robot perceives in one room: every object with its category, properties, "
    "height, whether it lies on the floor or near the edge of a surface, whether a small child could "
    "reach it, the state of doors, drawers and knobs, and how objects relate. Nobody has told you what is "
    "wrong. Find the situations that are dangerous or unhygienic for the people living there and that the "
    "robot could put right by picking, placing, closing or switching something off. Ignore ordinary "
    "objects that are where they belong. Put the most serious problem first."
)


def class_menu(kb) -> str:
    lines = [f"- {hc.id}: {hc.name}" for hc in sorted(kb.hazard_classes.values(), key=lambda h: h.id)]
    return "Known hazard classes (use the id in hazard_class, or null if none fits):\n" + "\n".join(lines)


def reply_schema(graph: SceneGraph, class_ids: list[str], k: int) -> type[BaseModel]:
    """A reply model whose enums are this scene's objects and the known classes, so bad names fail validation."""
    names = sorted({o.name for o in graph.objects} | {o.category for o in graph.objects})
    Target = Literal[tuple(names)] if names else str  # type: ignore[valid-type]
    Klass = Literal[tuple(sorted(class_ids))] if class_ids else str  # type: ignore[valid-type]
    draft = create_model(
        "HazardHypothesis",
        __config__=ConfigDict(extra="forbid"),
        problem=(str, Field(min_length=3, max_length=400, description="what is wrong and who could be hurt")),
        solution=(str, Field(min_length=3, max_length=400, description="what the robot should do about it")),
        target_object=(Target, Field(description="name of the scene object at fault")),
        hazard_class=(Klass | None, Field(None, description="id of the matching hazard class, or null")),
    )
    return create_model(
        "SceneHazards",
        __config__=ConfigDict(extra="forbid"),
        hypotheses=(list[draft], Field(min_length=1, max_length=k, description=f"1 to {k} problems, most serious first")),
    )


def user_prompt(graph: SceneGraph, kb, k: int) -> str:
    return (
        f"{observation_text(graph)}\n\n{class_menu(kb)}\n\n"
        f"List up to {k} problems in this room, most serious first. For each give the problem, the fix, "
        "the exact name of the object at fault (as written above) and the hazard class id."
    )


class LLMDetector:
    name = "llm"

    def __init__(self, client, kb=None, *, temperature: float | None = 0.0, seed: int | None = 0):
        self.client = client
        self.kb = kb
        self.temperature = temperature
        self.seed = seed

    def detect(self, graph: SceneGraph, k: int) -> list[Hypothesis]:
        kb = self.kb if self.kb is not None else _kb()
        schema = reply_schema(graph, list(kb.hazard_classes), k)
        reply = self.client.complete(
            [{"role": "system", "content": SYSTEM_PROMPT}, {"role": "user", "content": user_prompt(graph, kb, k)}],
            schema=schema,
            temperature=self.temperature,
            seed=self.seed,
        )
        out: list[Hypothesis] = []
        seen: set[tuple[str, str | None]] = set()
        for h in reply.hypotheses[:k]:
            key = (h.target_object, h.hazard_class)
            if key in seen:  # the same point twice adds nothing to hit@k
                continue
            seen.add(key)
            out.append(
                Hypothesis(
                    rank=len(out) + 1,
                    problem=h.problem,
                    solution=h.solution,
                    target_object=h.target_object,
                    hazard_class=h.hazard_class,
                    score=round(1.0 - 0.1 * len(out), 3),
                    explanation=f"LLM ({self.client.model})",
                )
            )
        return out


def _kb():
    from anomalygen.knowledge import load_kb

    return load_kb()
