"""The LLM detector: the paper's stage 3 — show the model the scene, ask for up to k problems and fixes.

The model sees the observation (objects, states, relations; never the task) and the knowledge base's
list of hazard classes, and answers with structured hypotheses through the LLM layer. Its reply is
untrusted: the reply schema is built per scene and grounds every name as it validates
(``knowledge.grounding``): ``target_object`` "fridge" becomes the scene's ``refrigerator_0``, a loose
class name becomes the closest class id (or null when none fits). Only a name that even retrieval
cannot place goes back to the model with the validation error (the LLM layer's repair loop), and a
scene whose replies never validate fails alone (``LLMItemError``), never the batch.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, create_model, model_validator

from anomalygen.detect.asking import AskingDetector
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


def reply_schema(graph: SceneGraph, grounder, k: int, notes: list[str] | None = None) -> type[BaseModel]:
    """A reply model that grounds each hypothesis's object and class names while it validates.

    ``notes`` collects one line per name that was not written exactly (kept in the hypotheses'
    explanations, so a detection says how its names were resolved)."""
    vocab = grounder.instances([(o.name, o.category) for o in graph.objects])
    names = sorted({o.name for o in graph.objects} | {o.category for o in graph.objects})
    class_ids = sorted(grounder.kb.hazard_classes)
    notes = notes if notes is not None else []

    def ground(model):
        context = f"{model.problem} {model.solution}"
        m = vocab.ground(model.target_object, "target_object", query=f"{model.target_object}. {context}")
        if m.grounded is None:
            raise ValueError(
                f"target_object '{model.target_object}' is not an object in this scene (closest: "
                f"{', '.join(m.alternatives[:2]) or '-'}); use one of {', '.join(names)}"
            )
        if m.method != "exact":
            notes.append(f"'{m.written}' -> {m.grounded} ({m.method})")
        model.target_object = m.grounded
        if model.hazard_class is not None:
            c = grounder.hazard_class(model.hazard_class, context, hazard_objects=[_category(graph, m.grounded)])
            if c.method != "exact":
                notes.append(f"class '{c.written}' -> {c.grounded} ({c.method})")
            model.hazard_class = None if c.grounded == "other" else c.grounded
        return model

    draft = create_model(
        "HazardHypothesis",
        __config__=ConfigDict(extra="forbid", validate_assignment=False),
        __validators__={"ground": model_validator(mode="after")(ground)},
        problem=(str, Field(min_length=3, max_length=400, description="what is wrong and who could be hurt")),
        solution=(str, Field(min_length=3, max_length=400, description="what the robot should do about it")),
        # The names stay in the JSON schema as enums, so a backend with grammar-constrained decoding
        # (llama.cpp) still writes an exact name; servers that ignore them get grounded instead.
        target_object=(str, Field(description="name of the scene object at fault, as written in the observation",
                                  json_schema_extra={"enum": names})),
        hazard_class=(str | None, Field(None, description="id of the matching hazard class, or null",
                                        json_schema_extra=lambda js: js.update(anyOf=[{"type": "string", "enum": class_ids},
                                                                                      {"type": "null"}]))),
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


class LLMDetector(AskingDetector):
    name = "llm"

    def detect(self, graph: SceneGraph, k: int) -> list[Hypothesis]:
        from anomalygen.knowledge.grounding import NameGrounder, shared_grounder

        kb = self.kb if self.kb is not None else _kb()
        notes: list[str] = []
        schema = reply_schema(graph, shared_grounder() if self.kb is None else NameGrounder(kb), k, notes)
        reply = self.ask(SYSTEM_PROMPT, user_prompt(graph, kb, k), schema)
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
                    explanation=f"LLM ({self.client.model})" + (f"; grounded {'; '.join(notes)}" if notes else ""),
                )
            )
        return out


def _kb():
    from anomalygen.knowledge import load_kb

    return load_kb()


def _category(graph: SceneGraph, name: str) -> str:
    return next((o.category for o in graph.objects if o.name == name), name)
