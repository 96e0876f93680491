"""Free-text tasks (``brainstorm --tasks-text FILE``): one plain description per line, grounded offline.

A person writes "Grandma's pills are on the coffee table" rather than a TaskProposal. Without a model,
the same grounding the LLM engine uses reads the line: the object, room and placement it mentions
(spelling and aliases), the hazard class by Sentence-BERT retrieval among the classes its objects can
be the hazard of, and, when no object is named, the class's hazard object retrieved from the text.
The rest of the scenario (target asset, container, person) is filled from the knowledge base so the
proposal can be built; the line itself stays the description. With an LLM configured, the LLM
engine structures each line instead (``LLMEngine.from_texts``) and grounds its names the same way.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from anomalygen.brainstorm.idea import Texts, task_id, to_proposal
from anomalygen.brainstorm.idea_sampler import IdeaSampler, class_targets
from anomalygen.brainstorm.realise import realise
from anomalygen.errors import UserError
from anomalygen.knowledge import KnowledgeBase
from anomalygen.knowledge.grounding import NameGrounder
from anomalygen.rng import item_rng
from anomalygen.schema import BrainstormMode, Engine, GroundingMatch, TaskProposal

WHERE = "text"


def read_lines(path: str | Path) -> list[str]:
    """The non-empty lines of a text file (``#`` starts a comment line)."""
    path = Path(path)
    if not path.is_file():
        raise UserError(f"{path}: no such file")
    lines = [ln.strip() for ln in path.read_text(encoding="utf-8").splitlines()]
    lines = [ln for ln in lines if ln and not ln.startswith("#")]
    if not lines:
        raise UserError(f"{path}: no task descriptions in the file")
    return lines


class TextGrounder:
    """Turns one plain description into a buildable TaskProposal, recording every grounding step."""

    def __init__(self, kb: KnowledgeBase, grounder: NameGrounder | None = None, *, seed: int = 0):
        self.kb = kb
        self.g = grounder or NameGrounder(kb)
        self.seed = seed
        self.filler = IdeaSampler(kb, None, rich=False)

    def hazard_and_class(self, line: str) -> tuple[str, str, list[GroundingMatch]]:
        """(class id, hazard object, matches); raises ValueError when no class fits the text."""
        kb, g = self.kb, self.g
        mentioned = g.objects.mentions(line)
        cls = g.hazard_class("", line, hazard_objects=mentioned).model_copy(update={"written": line})
        if cls.grounded in (None, "other"):
            raise ValueError(f"fits no hazard class (closest {cls.alternatives[:1] or ['-']}, similarity {cls.similarity:.2f})")
        hc = kb.hazard_classes[cls.grounded]
        candidates = kb.hazard_candidates(hc)
        named = [m for m in mentioned if m in candidates]
        if named:  # the text names it (by spelling or alias)
            hazard = GroundingMatch(field="scenario.hazard_object", written=line, grounded=named[0], method="normalised")
        else:  # the text only describes it: the class's candidate closest to the words
            ranked = g.objects.ranked(line, set(candidates), 3)
            hazard = GroundingMatch(
                field="scenario.hazard_object", written=line, grounded=ranked[0][0], method="retrieval",
                similarity=round(ranked[0][1], 4), alternatives=[n for n, _ in ranked[1:]],
            )
        return hc.id, hazard.grounded or candidates[0], [cls, hazard]

    def proposal(self, line: str, index: int) -> TaskProposal:
        kb, g = self.kb, self.g
        class_id, hazard, matches = self.hazard_and_class(line)
        hc = kb.hazard_classes[class_id]
        mentioned = g.objects.mentions(line)
        targets = class_targets(kb, hc)
        target = next((m for m in [hazard, *mentioned] if m in targets), targets[0])
        rng = item_rng(self.seed, "tasks-text", index)
        idea = self.filler.idea_for(rng, hc, target, agent=None, agent_index=0, round_=1)
        placements = kb.placements_for(hc, hazard)
        said = g.placements.mentions(line, placements)
        placement = said[0] if said else (g.placements.ranked(line, set(placements), 1) or [(placements[0], 0.0)])[0][0]
        rooms = g.rooms.mentions(line)
        room = rooms[0] if rooms else ([r for r in hc.rooms if r in kb.objects[hazard].rooms] or list(hc.rooms) or [idea.room])[0]
        containers = kb.containers_for(hc, hazard)
        container = next((m for m in mentioned if m in containers), containers[0] if containers else None)
        idea = replace(idea, hazard=hazard, placement=placement, room=room, container=container, co_objects=idea.co_objects)
        matches += [
            GroundingMatch(field="target_asset", written=line, grounded=target, method="class_default" if target not in mentioned else "normalised"),
            GroundingMatch(field="scenario.placement", written=line, grounded=placement, method="normalised" if said else "retrieval"),
            GroundingMatch(field="scenario.room", written=line, grounded=room, method="normalised" if rooms else "class_default"),
        ]
        words = realise(idea, kb, rng, perspective=False)
        texts = Texts(words.name, words.explanation, line, words.solution, words.success_condition)
        proposal = to_proposal(idea, texts, index, kb, engine=Engine.KNOWLEDGE, mode=BrainstormMode.PLAIN, seed=self.seed)
        return proposal.model_copy(update={"grounding": matches, "id": task_id(index, line)})


def tasks_from_lines(lines: list[str], kb: KnowledgeBase, *, seed: int = 0) -> tuple[list[TaskProposal], dict[str, str]]:
    """One proposal per line; a line that fits no class fails alone (``line<N>``: reason)."""
    tg = TextGrounder(kb, seed=seed)
    tasks: list[TaskProposal] = []
    errors: dict[str, str] = {}
    for n, line in enumerate(lines, start=1):
        try:
            tasks.append(tg.proposal(line, len(tasks) + 1))
        except ValueError as exc:
            errors[f"line{n}"] = f"'{line[:60]}': {exc}"
    return tasks, errors
