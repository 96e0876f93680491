"""Grounding: resolve the loose names a model (or a person) writes to knowledge-base names.

The paper lets the LLM name and describe objects freely and then retrieves catalogue assets with
Sentence-BERT; rejecting every slip ("kettle" for ``Kettle``, "cabinet" for ``StorageFurniture``)
sends the model round a repair loop that small models never leave. So every name goes through the
same ladder before validation: exact name, normalised spelling (case, plural, separators), the alias
table (``data/knowledge/aliases.json``), then the Sentence-BERT top-k over the knowledge base's
descriptions. Only a retrieval below the threshold is sent back for repair. Each step is recorded as
a ``GroundingMatch`` so the artefact says how a name was resolved.

One module for every LLM engine: brainstorming, the scene stage, detection and planning all ground
object names with ``NameGrounder.object`` and hazard classes with ``NameGrounder.hazard_class``.
"""

from __future__ import annotations

import functools
import json
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field

import numpy as np

from anomalygen.knowledge.base import KnowledgeBase
from anomalygen.knowledge.models import ROOMS
from anomalygen.schema import GroundingMatch, HazardCategory, Placement, object_relation

#: Cosine similarity a retrieved object must reach to be accepted without a repair round. Measured
#: with all-MiniLM-L6-v2: "coffee mug" -> mug 0.78, "sofa" -> Chair 0.52, while words naming nothing
#: in the catalogue stay lower ("flux capacitor" 0.29, "cat" 0.38, "spaceship" 0.40).
OBJECT_THRESHOLD = 0.45
#: A catalogue object found only by retrieval must be this similar and this far ahead of the runner-up
#: (cosine, all-MiniLM-L6-v2). Measured: "coffee mug" -> mug 0.78 (next 0.69), "carving knife" ->
#: Knife 0.79, "flower vase" -> vase 0.68 are kept; "sofa" -> Chair 0.52, "curling iron" -> iron 0.53,
#: "bin bag" -> TrashCan 0.55, "knife block" -> Knife 0.70 (next 0.66), "pill box" -> pill 0.61 (next
#: 0.59) are look-alikes and go back to the model or fail the item.
RETRIEVAL_FLOOR = 0.6
RETRIEVAL_MARGIN = 0.05
#: Similarity a free-text hazard needs to be filed under a class rather than ``other``.
CLASS_THRESHOLD = 0.35
#: Words that name no class at all: the hazard is then read from the proposal's own text.
GENERIC_CLASS_WORDS = frozenset({"", "other", "hazard", "unknown", "none", "general", "misc", "safety", "anomaly"})

#: What each placement on or at a support kind means, in words, for retrieval of free phrasings
#: ("perched at the counter's rim"); keyed by its compact word (``Placement.key``), in the order the
#: grounder's vocabulary and the LLM engine's prompt list them (``tests/test_schema.py`` checks that
#: it names every word of ``schema.SUPPORT_PLACEMENTS``).
PLACEMENT_TEXTS: dict[str, str] = {
    "floor": "lying on the floor",
    "walkway": "on the floor in a walkway, hallway or doorway where people walk",
    "table": "on a table or desk",
    "low_table": "on a low coffee table or bedside table a small child can reach",
    "table_edge": "at the very edge of a table, about to fall off",
    "counter": "on the kitchen counter",
    "counter_edge": "at the edge of the kitchen counter, overhanging",
    "shelf": "on a high shelf",
    "shelf_edge": "at the very edge of a high shelf, about to fall",
}
#: The relations to another object whose object the grounder grounds in a written placement
#: (``inside:<object>``, ``on:<object>``); the LLM engine offers the model these.
GROUNDED_RELATIONS: tuple[str, ...] = ("inside", "on")

_SPLIT_CAMEL = re.compile(r"(?<=[a-z0-9])(?=[A-Z])")
_NON_WORD = re.compile(r"[^a-z0-9]+")
_WORD = re.compile(r"[a-z0-9]+(?:'[a-z]+)?")


def normalise(text: str) -> str:
    """``"Kitchen Pot"``, ``"kitchen-pot"``, ``"KitchenPot"`` and ``"kitchen_pots"`` all become ``kitchen_pot``."""
    words = _NON_WORD.sub(" ", _SPLIT_CAMEL.sub(" ", text.strip()).lower()).split()
    if words:
        words[-1] = singular(words[-1])
    return "_".join(words)


def name_words(name: str) -> str:
    """A catalogue name as words, its case kept: 'toy_block' -> 'toy block', 'PaperTowels' -> 'Paper Towels'."""
    return re.sub(r"(?<=[a-z])(?=[A-Z])", " ", name).replace("_", " ")


def singular(word: str) -> str:
    """English plural of the last word undone, for the common regular forms only."""
    if len(word) <= 3 or word.endswith(("ss", "us", "is")):
        return word
    if word.endswith("ives"):
        return word[:-3] + "fe"  # knives -> knife
    if word.endswith("ies"):
        return word[:-3] + "y"
    if word.endswith(("ches", "shes", "xes", "sses")):
        return word[:-2]
    if word.endswith("s"):
        return word[:-1]
    return word


def words_of(name: str) -> str:
    """A name as words, for embedding and prompts: ``StorageFurniture`` -> ``storage furniture``."""
    return normalise(name).replace("_", " ")


@functools.cache
def _aliases() -> dict[str, dict[str, str]]:
    from importlib.resources import files

    raw = json.loads(files("anomalygen.data.knowledge").joinpath("aliases.json").read_text(encoding="utf-8"))
    return {kind: {normalise(k): v for k, v in table.items()} for kind, table in raw.items() if not kind.startswith("_")}


@dataclass
class Vocabulary:
    """A closed set of names with one text each, grounded by spelling, aliases and retrieval."""

    kind: str
    names: list[str]
    texts: list[str]
    aliases: dict[str, str] = field(default_factory=dict)
    threshold: float = OBJECT_THRESHOLD
    margin: float = 0.0  # how far the best retrieval must lead the second to count
    _keys: dict[str, str] = field(default_factory=dict, init=False, repr=False)
    _vecs: np.ndarray | None = field(default=None, init=False, repr=False)

    def __post_init__(self) -> None:
        self._keys = {normalise(n): n for n in self.names}

    def vectors(self) -> np.ndarray:
        if self._vecs is None:
            from anomalygen.embedding import embed

            self._vecs = embed(self.texts)
        return self._vecs

    def spelled(self, written: str, among: set[str]) -> tuple[str, str] | None:
        """``(name, method)`` when the name is exact, differently spelled or a known alias."""
        if written in among:
            return written, "exact"
        key = normalise(written)
        name = self._keys.get(key)
        if name in among:
            return name, "normalised"
        name = self.aliases.get(key)
        if name in among:
            return name, "alias"
        return None

    def mentions(self, text: str, among: Iterable[str] | None = None, *, longest: int = 3) -> list[str]:
        """Names the text mentions by spelling or alias, in order, longest phrase first where they overlap.

        "A chef's knife on the kitchen counter" mentions ``kitchen_knife`` and ``counter``: the scan
        reads word n-grams (possessives dropped), so free text needs no model to find its objects.
        """
        pool = set(self.names) if among is None else set(among)
        words = [w.removesuffix("'s") for w in _WORD.findall(text.lower())]
        taken = [False] * len(words)
        found: list[tuple[int, str]] = []
        for n in range(longest, 0, -1):
            for i in range(len(words) - n + 1):
                if any(taken[i : i + n]):
                    continue
                hit = self.spelled(" ".join(words[i : i + n]), pool)
                if hit is not None:
                    found.append((i, hit[0]))
                    taken[i : i + n] = [True] * n
        return list(dict.fromkeys(name for _, name in sorted(found)))

    def ranked(self, query: str, among: set[str], k: int) -> list[tuple[str, float]]:
        """The Sentence-BERT top-k of ``among`` for ``query``: the paper's retrieval step."""
        from anomalygen.embedding import embed

        idx = [i for i, n in enumerate(self.names) if n in among]
        if not idx or not query.strip():
            return []
        sims = self.vectors()[idx] @ embed([query])[0]
        order = np.argsort(-sims, kind="stable")[:k]
        return [(self.names[idx[int(j)]], float(sims[int(j)])) for j in order]

    def ground(self, written: str, where: str, *, among: Iterable[str] | None = None, query: str | None = None, k: int = 5) -> GroundingMatch:
        """The best match; ``grounded`` is None when even retrieval stays below the threshold."""
        pool = set(self.names) if among is None else set(among)
        hit = self.spelled(written, pool)
        if hit is not None:
            return GroundingMatch(field=where, written=written, grounded=hit[0], method=hit[1])  # type: ignore[arg-type]
        ranked = self.ranked(query or words_of(written), pool, k)
        if not ranked:
            return GroundingMatch(field=where, written=written, grounded=None, method="retrieval", similarity=0.0)
        best, sim = ranked[0]
        lead = sim - ranked[1][1] if len(ranked) > 1 else 1.0
        return GroundingMatch(
            field=where,
            written=written,
            grounded=best if sim >= self.threshold and lead >= self.margin else None,
            method="retrieval",
            similarity=round(sim, 4),
            alternatives=[n for n, _ in ranked[1:]],
        )


class NameGrounder:
    """Grounds objects, rooms, placements and hazard classes against one knowledge base."""

    def __init__(self, kb: KnowledgeBase, *, object_threshold: float = RETRIEVAL_FLOOR, class_threshold: float = CLASS_THRESHOLD):
        self.kb = kb
        aliases = _aliases()
        self.objects = Vocabulary(
            "object",
            list(kb.objects),
            [f"{words_of(n)}: {info.description}" for n, info in kb.objects.items()],
            aliases.get("objects", {}),
            object_threshold,
            RETRIEVAL_MARGIN,
        )
        self.rooms = Vocabulary("room", list(ROOMS), [words_of(r) for r in ROOMS], aliases.get("rooms", {}), OBJECT_THRESHOLD)
        self.placements = Vocabulary(
            "placement", list(PLACEMENT_TEXTS), list(PLACEMENT_TEXTS.values()), aliases.get("placements", {}),
            OBJECT_THRESHOLD,
        )
        self.classes = Vocabulary(
            "class",
            list(kb.hazard_classes),
            [f"{hc.name}: {hc.mechanism}. {hc.why} At risk: {hc.at_risk}." for hc in kb.hazard_classes.values()],
            {},
            class_threshold,
        )

    def object(self, written: str, where: str, *, among: Sequence[str] | None = None, query: str | None = None) -> GroundingMatch:
        return self.objects.ground(written, where, among=among, query=query)

    def instances(self, objects: Sequence[tuple[str, str]]) -> Vocabulary:
        """A vocabulary of one scene's instances ``(name, category)``: "kettle", "the fridge" or
        "electric kettle" find ``kettle_0`` through its category, the alias table or retrieval."""
        aliases: dict[str, str] = {}
        for name, category in objects:
            aliases.setdefault(normalise(category), name)
            for key, target in self.objects.aliases.items():
                if target == category:
                    aliases.setdefault(key, name)
        texts = [
            f"{words_of(category)}: {self.kb.objects[category].description if category in self.kb.objects else ''}"
            for _, category in objects
        ]
        return Vocabulary("scene object", [n for n, _ in objects], texts, aliases, OBJECT_THRESHOLD)

    def target(self, written: str, where: str = "target_asset") -> GroundingMatch:
        return self.objects.ground(written, where, among=self.kb.targets)

    def room(self, written: str, where: str = "scenario.room") -> GroundingMatch:
        return self.rooms.ground(written, where)

    def is_room(self, written: str) -> bool:
        """A room written where an object belongs ("kitchen" as a co-object) is context, not a thing."""
        return self.rooms.spelled(written, set(ROOMS)) is not None

    def placement(self, written: str, where: str = "scenario.placement") -> GroundingMatch:
        """A placement, including ``inside:<object>`` / ``on:<object>`` with the object grounded too;
        ``grounded`` is its compact word (``Placement`` reads it)."""
        split = object_relation(written)
        if split is not None and split[0] in GROUNDED_RELATIONS:
            relation, other = split
            inner = self.object(other, where)
            grounded = Placement(relation=relation, other=inner.grounded).key if inner.grounded else None
            return inner.model_copy(update={"written": written, "grounded": grounded})
        return self.placements.ground(written, where)

    def classes_with_hazard(self, obj: str) -> set[str]:
        """Classes whose hazard variable ``obj`` can fill (a pill is a medication, not a chemical)."""
        return {hc.id for hc in self.kb.hazard_classes.values() if obj in self.kb.hazard_candidates(hc)}

    def hazard_class(
        self, written: str, context: str, *, category: str | None = None, hazard_objects: Iterable[str] = (), where: str = "hazard_class"
    ) -> GroundingMatch:
        """A class id; a generic word or a category name is read from ``context`` (the proposal's text).

        With grounded ``hazard_objects`` retrieval only considers the classes they can be the hazard
        of, when there are any, and takes the best of those even below the threshold: a named object
        is stronger evidence than the wording. Returns ``method="other"`` (grounded ``"other"``) when
        nothing fits well enough: the caller keeps the model's own words as ``hazard_other``.
        """
        all_ids = set(self.kb.hazard_classes)
        hit = self.classes.spelled(written, all_ids)
        if hit is not None:
            return GroundingMatch(field=where, written=written, grounded=hit[0], method=hit[1])  # type: ignore[arg-type]
        key = normalise(written)
        categories = {c.value for c in HazardCategory}
        among = all_ids
        if key in categories or (category in categories and key in GENERIC_CLASS_WORDS):
            cat = key if key in categories else category
            among = {hc.id for hc in self.kb.classes_in(cat)}
        fitting = {c for obj in hazard_objects for c in self.classes_with_hazard(obj)}
        among = (among & fitting) or fitting or among
        query = context if key in GENERIC_CLASS_WORDS or key in categories else f"{written.replace('_', ' ')}. {context}"
        match = self.classes.ground(written, where, among=among, query=query)
        if match.grounded is None and fitting and match.similarity > 0:
            match = match.model_copy(update={"grounded": self.classes.ranked(query, among, 1)[0][0]})
        if match.grounded is None:
            return match.model_copy(update={"grounded": "other", "method": "other"})
        return match


@functools.cache
def shared_grounder() -> NameGrounder:
    """One grounder per process over the packaged knowledge base (its embeddings are computed once)."""
    from anomalygen.knowledge.base import load_kb

    return NameGrounder(load_kb())
