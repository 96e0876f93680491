"""An LLM as the agent: the paper's detection prompt plus the skill vocabulary, one call per reply.

Each step the configured backend (``[llm]``: OpenAI-compatible, Anthropic or the local GGUF) is shown
the scene as the LLM detector is shown it (the paper's textual scene description, the class menu;
with ``images`` and a vision endpoint, the front camera's image too), the skills and the parts it may
name, and what its earlier calls did; it answers with the most serious problem it still sees and one
call. The reply is untrusted: a per-scene schema (object names as enums, so grammar-constrained
backends write real names) checks the call as the env would (``agents/vocabulary.py``); an invalid
reply goes back with the error (the LLM layer's repair loop), and one that stays invalid fails that
step only: the agent hands the env an action it refuses, the env says why in ``info["error"]`` and
the episode goes on. The problems it named are its reported detections.
"""

from __future__ import annotations

import io

from pydantic import BaseModel, ConfigDict, Field, PrivateAttr, create_model, model_validator

from anomalygen.agents.base import Agent
from anomalygen.agents.vocabulary import (
    DONE,
    FIX,
    VOCABULARY,
    WAIT,
    Call,
    CallError,
    SceneView,
    validate_call,
)

INSTRUCTIONS = (
    "You act through the robot's skills, one call at a time. Each turn, say the most serious problem you "
    "still see (or 'nothing' when all is safe) and choose one skill with its arguments, using the object "
    "and part names exactly as written. Choose skill 'done' when nothing is left to put right: acting on "
    "objects that are safe counts against you."
)
SKILLS = tuple(name for name in VOCABULARY if name != WAIT)


class _Turn(BaseModel):
    """A reply; its validator keeps the call it read in ``call``."""

    model_config = ConfigDict(extra="forbid")
    _call: Call | None = PrivateAttr(None)

    @property
    def call(self) -> Call:
        return self._call


def reply_schema(view: SceneView, kb) -> type[BaseModel]:
    """A reply model whose validation builds the call and checks it as the env will."""
    names = sorted(view.objects)
    classes = sorted(kb.hazard_classes)

    def enum(values, text):
        return Field(None, description=text, json_schema_extra=lambda js: js.update(
            anyOf=[{"type": "string", "enum": list(values)}, {"type": "null"}]))

    def check(model):
        model._call = validate_call(to_call(model), view, kb)
        return model

    return create_model(
        "AgentTurn",
        __base__=_Turn,
        __validators__={"check": model_validator(mode="after")(check)},
        problem=(str, Field(min_length=1, max_length=400, description="what is wrong and who could be hurt, or 'nothing'")),
        target_object=(str | None, enum(names, "the object at fault, or null")),
        hazard_class=(str | None, enum(classes, "id of the matching hazard class, or null")),
        skill=(str, Field(description="one skill of the list", json_schema_extra={"enum": list(SKILLS)})),
        object=(str | None, enum(names, "the object the skill acts on")),
        destination=(str | None, enum(names, "where it goes (pick_place, take_out, push_to), what it must be away "
                                         "from (move_away), the surface (take_off)")),
        container=(str | None, enum(names, "take_out only: what it is in")),
        part=(str | None, Field(None, max_length=64, description="open, close, switch_off: a part's name or label")),
    )


def to_call(turn) -> Call:
    """The reply's fields as a call of the vocabulary (CallError when a needed field is missing)."""
    s = turn.skill
    if s not in VOCABULARY:
        raise CallError(f"unknown skill {s!r}")
    args: dict = {}
    if s not in (DONE, WAIT):
        args["object"] = turn.object
    if s in ("pick_place", "take_out", "push_to"):
        args["destination"] = turn.destination
    if s == "take_out":
        args["container"] = turn.container
    if s == "move_away":
        args["from"] = turn.destination
    if s == "take_off" and turn.destination:
        args["support"] = turn.destination
    if s in ("open", "close", "switch_off") and turn.part:
        args["part"] = turn.part
    if s == FIX:
        args["hazard_class"] = turn.hazard_class
    missing = [k for k, v in args.items() if v is None]
    if missing:
        raise CallError(f"{s} needs {', '.join(missing)}: {VOCABULARY[s].signature()}")
    return Call(skill=s, args=args)


class LLMAgent(Agent):
    """The configured LLM (``[llm]``), one call per reply; its named problems are its detections."""

    observe = ("image", "scene_text", "objects")

    def __init__(self, settings=None, images: bool | None = None, client=None):
        from anomalygen.config import Settings

        self.settings = settings if settings is not None else Settings()
        self._client = client
        self.images = images
        self.history: list[str] = []
        self.found: list = []

    @property
    def client(self):
        if self._client is None:
            from anomalygen.errors import UserError
            from anomalygen.llm import shared_client

            if not self.settings.llm.configured:
                raise UserError("the LLM agent needs an LLM: set [llm] backend (openai, anthropic or llamacpp)")
            self._client = shared_client(self.settings.llm)
        return self._client

    def reset(self, obs, info):
        self.history, self.found = [], []

    def act(self, obs):
        from anomalygen.detect.llm_detector import SYSTEM_PROMPT, class_menu
        from anomalygen.knowledge import load_kb
        from anomalygen.llm import LLMItemError

        kb = load_kb()
        view = SceneView.from_objects(obs["objects"])
        skills = "\n".join(f"- {VOCABULARY[s].signature()}: {VOCABULARY[s].doc}" for s in SKILLS)
        system = f"{SYSTEM_PROMPT}\n\n{INSTRUCTIONS}\n\nSkills:\n{skills}\n\n{class_menu(kb)}"
        messages = [{"role": "system", "content": system}, {"role": "user", "content": self._user(obs)}]
        images = [_png(obs["image"])] if self._with_images() and "image" in obs else None
        try:
            turn = self.client.complete(messages, schema=reply_schema(view, kb), images=images, seed=self.settings.seed)
        except LLMItemError as exc:
            self.history.append(f"- your reply was not a valid call: {exc}")
            return f"no valid reply: {exc}"  # the env refuses it: this step fails, the episode goes on
        self._note(turn)
        self.history.append(f"- {turn.call.text()}")
        return turn.call

    def result(self, info: dict) -> None:
        """What the env said about the last call: kept for the next prompt."""
        if self.history and info.get("error"):
            self.history[-1] += f" -> refused: {info['error']}"
        elif self.history and info.get("executed"):
            ok = all(r["success"] for r in info["executed"])
            self.history[-1] += " -> done" if ok else " -> tried, its check failed"

    def detections(self):
        return list(self.found)

    def _with_images(self) -> bool:
        return self.client.supports_images if self.images is None else bool(self.images)

    def _user(self, obs) -> str:
        parts = [f"- {o['name']}: " + ", ".join(f"{p['name']} ({p['state']})" for p in o["parts"])
                 for o in obs["objects"] if o["parts"]]
        text = obs["scene_text"]
        if parts:
            text += "\nParts you can name:\n" + "\n".join(parts)
        if self.history:
            text += "\nWhat you did so far:\n" + "\n".join(self.history)
        return text

    def _note(self, turn) -> None:
        from anomalygen.schema import Hypothesis

        if turn.target_object is None or turn.problem.strip().lower().startswith("nothing"):
            return
        if any(h.target_object == turn.target_object and h.hazard_class == turn.hazard_class for h in self.found):
            return
        self.found.append(Hypothesis(rank=len(self.found) + 1, problem=turn.problem[:400], solution=turn.call.text(),
                                     target_object=turn.target_object, hazard_class=turn.hazard_class,
                                     score=1.0 / (len(self.found) + 1)))


def _png(image) -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(image).save(buf, format="PNG")
    return buf.getvalue()
