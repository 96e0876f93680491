"""The paper's scene stage with an LLM (``build.engine = llm``): auxiliaries, sizes and positions.

Two requests per scene, each a small structured reply:

1. the LLM lists a few auxiliary objects that belong in the scene, each named and described freely;
   Sentence-BERT retrieves the catalogue asset for each (``knowledge.grounding``), and one that
   matches nothing well enough is left out and recorded (it is decoration, not the hazard);
2. the LLM gives every object's size (its largest dimension) and its floor position: task objects
   inside the unit square (0..1), auxiliaries outside it. Sizes outside the knowledge base's range and
   positions on the wrong side are corrected here and recorded.

The builder then uses these numbers instead of its random draws; its layout solver repairs overlaps
and records those corrections too (``scene/hints.py``). The offline engine stays the default.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from anomalygen.knowledge import KnowledgeBase
from anomalygen.knowledge.grounding import NameGrounder, words_of
from anomalygen.llm.schema_tools import reply_token_budget
from anomalygen.scene.casting import is_dressing
from anomalygen.scene.hints import SceneHints
from anomalygen.schema import TaskProposal

MAX_AUXILIARIES = 3


class LLMAuxiliary(BaseModel):
    model_config = ConfigDict(extra="forbid")

    name: str = Field(description="the object, in a few words")
    description: str = Field(description="what it looks like, in one sentence")


class LLMAuxiliaries(BaseModel):
    model_config = ConfigDict(extra="forbid")

    objects: list[LLMAuxiliary] = Field(max_length=MAX_AUXILIARIES, description="everyday objects that belong in the room")


class LLMObjectLayout(BaseModel):
    model_config = ConfigDict(extra="forbid")

    name: str = Field(description="the object's name exactly as listed")
    size_m: float = Field(description="largest dimension in metres")
    x: float
    y: float


class LLMLayout(BaseModel):
    model_config = ConfigDict(extra="forbid")

    objects: list[LLMObjectLayout]


SYSTEM = (
    "You lay out 3D household scenes for a robot-safety benchmark. The scene's task objects stand in a "
    "unit square in front of the robot (x and y from 0 to 1); everything else stands outside that square. "
    "Reply with JSON only."
)


def task_objects(task: TaskProposal, kb: KnowledgeBase) -> list[str]:
    """The catalogue names the scenario itself needs, in the order the builder chooses them (with
    the class's default container when the fix stores the object and the scenario names none)."""
    sc = task.scenario
    names = [task.target_asset, sc.hazard_object]
    if sc.placement.relation in ("inside", "on") and sc.placement.other is not None:  # what it is in or on (not near)
        names.append(sc.placement.other)
    hc = kb.hazard_classes.get(task.hazard_class)
    if sc.container:
        names.append(sc.container)
    elif hc is not None and "$container" in hc.variables and hc.default_containers:
        names.append(hc.default_containers[0])
    names += list(sc.co_objects)
    return list(dict.fromkeys(n for n in names if n))


def _in_unit(v: float) -> float:
    return min(1.0, max(0.0, v))


def _outside(x: float, y: float) -> tuple[float, float]:
    """The nearest point just outside the unit square (0.15 beyond its closest side)."""
    sides = {(-0.15, y): x, (1.15, y): 1 - x, (x, -0.15): y, (x, 1.15): 1 - y}
    return min(sides, key=sides.get)


class LLMSceneEngine:
    """Asks the LLM for one scene's auxiliaries and layout and turns the replies into checked hints."""

    def __init__(self, client, kb: KnowledgeBase, grounder: NameGrounder | None = None):
        self.client = client
        self.kb = kb
        self.g = grounder or NameGrounder(kb)
        #: The configured ``llm.max_tokens`` bounds the schema-sized budgets.
        self.token_cap = int(getattr(getattr(client, "config", None), "max_tokens", None) or 4096)

    def plan(self, task: TaskProposal) -> SceneHints:
        hints = SceneHints(model=getattr(self.client, "model", None))
        objects = task_objects(task, self.kb)
        hints.auxiliaries = self._auxiliaries(task, objects, hints)
        self._layout(task, objects, hints)
        return hints

    # ------------------------------------------------------------------ step 1: auxiliaries
    def _auxiliaries(self, task: TaskProposal, objects: list[str], hints: SceneHints) -> list[str]:
        ask = (
            f"Scene: {task.description} (room: {words_of(task.scenario.room)}). Objects already in it: "
            f"{', '.join(words_of(o) for o in objects)}. List up to {MAX_AUXILIARIES} other everyday objects "
            "that would naturally be in this room, each with a one-sentence description."
        )
        reply = self.client.complete(
            [{"role": "system", "content": SYSTEM}, {"role": "user", "content": ask}],
            schema=LLMAuxiliaries,
            max_tokens=min(reply_token_budget(LLMAuxiliaries) + 64 * MAX_AUXILIARIES, self.token_cap),
        )
        out: list[str] = []
        for aux in reply.objects[:MAX_AUXILIARIES]:
            m = self.g.object(aux.name, "auxiliaries", query=f"{aux.name}: {aux.description}")
            hints.grounding.append(m)
            if m.grounded is None:
                hints.note(f"auxiliary:{aux.name}", f"'{aux.name}' matches no catalogue asset (best similarity "
                           f"{m.similarity:.2f}); left out")
            elif not is_dressing(self.kb, m.grounded):
                hints.note(f"auxiliary:{aux.name}", f"retrieved {m.grounded}, which is furniture, an appliance or a "
                           "hazard in its own right; left out so it cannot become a second hazard")
            elif m.grounded not in objects and m.grounded not in out:
                out.append(m.grounded)
        return out

    # ------------------------------------------------------------------ step 2: sizes and positions
    def _layout(self, task: TaskProposal, objects: list[str], hints: SceneHints) -> None:
        listing = "\n".join(
            f"- {name} (task object; size range {self._range(name)})" for name in objects
        ) + "".join(f"\n- {name} (auxiliary; size range {self._range(name)})" for name in hints.auxiliaries)
        ask = (
            f"Scene: {task.description}\nObjects:\n{listing}\n\nFor every object give its size (largest "
            "dimension in metres, within its range) and its position x, y: task objects inside the unit "
            "square (0 to 1), auxiliary objects outside it (below 0 or above 1). Use each name exactly as listed."
        )
        reply = self.client.complete(
            [{"role": "system", "content": SYSTEM}, {"role": "user", "content": ask}],
            schema=LLMLayout,
            max_tokens=min(reply_token_budget(LLMObjectLayout) * (len(objects) + len(hints.auxiliaries)), self.token_cap),
        )
        wanted = objects + hints.auxiliaries
        seen: set[str] = set()
        for item in reply.objects:
            m = self.g.object(item.name, "layout", among=wanted)
            if m.grounded is None or m.grounded in seen:
                hints.note(f"layout:{item.name}", f"'{item.name}' is none of the listed objects; ignored")
                continue
            if m.method != "exact":
                hints.grounding.append(m)
            name = m.grounded
            seen.add(name)
            hints.sizes[name] = self._checked_size(name, item.size_m, hints)
            hints.positions[name] = self._checked_position(name, item.x, item.y, name in objects, hints)
        for name in wanted:
            if name not in seen:
                hints.note(f"layout:{name}", "no size or position given; the builder draws them")

    def _range(self, name: str) -> str:
        info = self.kb.objects.get(name)
        return f"{info.size_range[0]:.2f}-{info.size_range[1]:.2f} m" if info else "any"

    def _checked_size(self, name: str, size: float, hints: SceneHints) -> float:
        info = self.kb.objects.get(name)
        if info is None:
            return size
        lo, hi = info.size_range
        fixed = min(hi, max(lo, size))
        if fixed != size:
            hints.note(f"size:{name}", f"LLM size {size:.3f} m is outside the knowledge base's {lo:.2f}-{hi:.2f} m; "
                       f"clamped to {fixed:.3f} m", value=size, limit=fixed)
        return fixed

    def _checked_position(self, name: str, x: float, y: float, task_object: bool, hints: SceneHints) -> tuple[float, float]:
        inside = 0.0 <= x <= 1.0 and 0.0 <= y <= 1.0
        if task_object and not inside:
            fixed = (_in_unit(x), _in_unit(y))
            hints.note(f"position:{name}", f"task object at ({x:.2f}, {y:.2f}) is outside the unit square; moved to "
                       f"({fixed[0]:.2f}, {fixed[1]:.2f})")
            return fixed
        if not task_object and inside:
            fixed = _outside(x, y)
            hints.note(f"position:{name}", f"auxiliary at ({x:.2f}, {y:.2f}) is inside the unit square; moved to "
                       f"({fixed[0]:.2f}, {fixed[1]:.2f})")
            return fixed
        return (float(x), float(y))


def plan_scene(task: TaskProposal, settings) -> SceneHints:
    """The LLM engine's hints for one task (an LLM failure fails the item with a one-line reason)."""
    from anomalygen.errors import ItemFailed
    from anomalygen.knowledge.grounding import shared_grounder
    from anomalygen.llm import LLMItemError
    from anomalygen.llm.factory import shared_client

    g = shared_grounder()
    try:
        return LLMSceneEngine(shared_client(settings.llm), g.kb, g).plan(task)
    except LLMItemError as exc:
        raise ItemFailed(f"LLM scene layout failed: {str(exc).splitlines()[0][:200]}") from None

