"""Free-text tasks (``brainstorm --tasks-text FILE``): one plain description per line, built as stated.

A person writes "Grandma's pills are on the coffee table" rather than a TaskProposal. Offline, each
line is read (``line_parse``) into the object at fault, the objects it relates to and the words that
say where and in what state, and the hazard is composed from the mechanisms (``line_compose``); the
names are the catalogue's own words or aliases, never a retrieved look-alike. A line that states no
hazard the mechanisms can build, or names an object the catalogue or its assets lack, fails alone
with a reason that names the closest thing; the other lines go on. Every choice is recorded in the
task's ``grounding`` (which words became which object, state, place and mechanism, and what was a
class default), the line itself is the description, and the task is marked ``source="user_text"``
so the builder adds no hazard-free variant and no second hazard. With an LLM configured, the LLM
engine structures each line instead (``LLMEngine.from_texts``) and grounds its names the same way.
"""

from __future__ import annotations

from pathlib import Path

from anomalygen.brainstorm.idea import Idea, Texts, task_id, to_proposal
from anomalygen.brainstorm.idea_sampler import IdeaSampler, class_targets
from anomalygen.brainstorm.line_compose import Composition, Refused, compose_line, placement_for
from anomalygen.brainstorm.line_parse import ParsedLine, parse_line
from anomalygen.brainstorm.realise import realise
from anomalygen.errors import UserError
from anomalygen.knowledge import KnowledgeBase
from anomalygen.knowledge.grounding import NameGrounder
from anomalygen.knowledge.lexicon import load_lexicon
from anomalygen.knowledge.mechanisms import load_mechanisms
from anomalygen.rng import item_rng
from anomalygen.schema import BrainstormMode, Engine, GroundingMatch, TaskProposal
from anomalygen.textfile import read_lines

USER_TEXT = "user_text"


# The longest line a --tasks-text file may hold. A hazard line is one description, a sentence or two
# (the test fixture's longest is 92 characters); 1,000 leaves room for a long paragraph, and stops a
# pasted document or a file with no line breaks before the parser and the embedder spend time on it.
MAX_LINE_CHARS = 1000


def read_task_lines(path: str | Path) -> list[str]:
    """The descriptions of a --tasks-text file: its non-blank lines (``#`` starts a comment line), read
    through ``anomalygen.textfile`` (a folder, a binary file, text not in UTF-8 or a line over
    ``MAX_LINE_CHARS`` is one ``UserError`` line)."""
    lines = [ln.strip() for ln in read_lines(path, what="--tasks-text file", max_chars=MAX_LINE_CHARS,
                                               limit_reason="one hazard, a sentence or two")]
    lines = [ln for ln in lines if ln and not ln.startswith("#")]
    if not lines:
        raise UserError(f"{path}: no task descriptions, only blank lines and # comments; write one hazard per line")
    return lines


class TextGrounder:
    """Turns one plain description into a buildable TaskProposal, recording every grounding step."""

    def __init__(self, kb: KnowledgeBase, grounder: NameGrounder | None = None, *, seed: int = 0,
                 catalogue: set[str] | None = None):
        self.kb = kb
        self.g = grounder or NameGrounder(kb)
        self.seed = seed
        self.ms = load_mechanisms()
        self.filler = IdeaSampler(kb, None, rich=False)
        self._catalogue = catalogue

    @property
    def catalogue(self) -> set[str]:
        if self._catalogue is None:
            from anomalygen.brainstorm.drawable import catalogue

            self._catalogue = set(catalogue())
        return self._catalogue

    def compose(self, line: str) -> tuple[ParsedLine, Composition]:
        """The line read and its hazard composed; raises Refused (a ValueError) with the reason."""
        parsed = parse_line(line, self.g, lexicon=load_lexicon(), buildable=self.catalogue)
        comp = compose_line(parsed, self.kb, self.ms, self.g)
        missing = [m.name for m in (comp.fault, comp.other) if m is not None and m.name not in self.catalogue]
        if missing:
            raise Refused(f"'{missing[0]}' is known but has no asset in the catalogue yet, so it cannot be built")
        return parsed, comp

    def proposal(self, line: str, index: int) -> TaskProposal:
        kb = self.kb
        parsed, comp = self.compose(line)
        hc = comp.hc
        hazard = comp.fault.name
        placement, placement_said = placement_for(parsed, hc, comp, self.ms)
        rooms_said = [r for r in parsed.rooms]
        fitting = [r for r in hc.rooms if r in kb.objects[hazard].rooms] or list(hc.rooms) or list(kb.objects[hazard].rooms)
        room = rooms_said[0] if rooms_said else (fitting[0] if fitting else "living_room")
        mentioned = [m.name for m in parsed.mentions]
        targets = class_targets(kb, hc)
        target = next((m for m in [hazard, *mentioned] if m in targets), targets[0] if targets else hazard)
        if hc.about_target:
            # the class's state (on, open) is set on its target: the line's object at fault is the
            # target, a category of the paper's 44 or not (a space heater left on is not an oven left on)
            target = hazard
        containers = kb.containers_for(hc, hazard)
        container = next((m for m in mentioned if m in containers), containers[0] if containers else None)
        support = next((s for s in hc.default_supports if s in mentioned), hc.default_supports[0] if hc.default_supports else None)
        others = self._others(hc, comp, mentioned, hazard, container)
        rng = item_rng(self.seed, "tasks-text", index)
        idea = Idea(class_id=hc.id, target=target, hazard=hazard, placement=placement, room=room, person=hc.at_risk,
                    container=container, support=support, co_objects=tuple(others))
        called = {m.name: m.called for m in (comp.fault, comp.other) if m is not None and m.called}
        words = realise(idea, kb, rng, called=called)
        texts = Texts(words.name, words.explanation, line, words.solution, words.success_condition)
        proposal = to_proposal(idea, texts, index, kb, engine=Engine.KNOWLEDGE, mode=BrainstormMode.PLAIN, seed=self.seed)
        if called:
            proposal = proposal.model_copy(update={"scenario": proposal.scenario.model_copy(update={"called": called})})
        matches = self._record(line, parsed, comp, placement, placement_said, room, bool(rooms_said), target,
                               container, mentioned)
        return proposal.model_copy(update={"grounding": matches, "id": task_id(index, line), "source": USER_TEXT})

    def _others(self, hc, comp: Composition, mentioned: list[str], hazard: str, container: str | None) -> list[str]:
        """Co-objects: the object each other precondition variable needs (the related one when the line
        names it), then whatever else the line names; nothing the line does not mention is added."""
        from anomalygen.brainstorm.drawable import relation_variable

        related = relation_variable(hc)
        out: list[str] = []
        for var in [v for v in hc.variable_names() if v != hc.hazard_variable]:
            if var == related and comp.other is not None:
                out.append(comp.other.name)
            elif var != "$target":
                fits = [m for m in mentioned if m in self.kb.static_candidates(hc, var)]
                out.append(fits[0] if fits else self.kb.static_candidates(hc, var)[0])
        for m in mentioned:
            if m not in out and m not in (hazard, container) and not self.g.is_room(m):
                out.append(m)
        return out

    def _record(self, line, parsed, comp: Composition, placement, placement_said, room, room_said, target,
                container, mentioned) -> list[GroundingMatch]:
        hc = comp.hc
        out = [GroundingMatch(field="scenario.hazard_object", written=comp.fault.words, grounded=comp.fault.name,
                              method="lexicon" if comp.fault.kind else "parsed", kind=comp.fault.kind)]
        if comp.other is not None:
            out.append(GroundingMatch(field=f"relation.{comp.other.relation}", written=f"{comp.other.prep} {comp.other.words}",
                                      grounded=comp.other.name, method="lexicon" if comp.other.kind else "parsed",
                                      kind=comp.other.kind))
        if comp.condition_words:
            out.append(GroundingMatch(field="state", written=", ".join(comp.condition_words),
                                      grounded=hc.composition.condition, method="parsed"))
        elif comp.assumed:
            out.append(GroundingMatch(field="state", written="", grounded=hc.composition.condition, method="class_default"))
        if comp.place_words:
            out.append(GroundingMatch(field="place", written=", ".join(comp.place_words), grounded=hc.composition.place,
                                      method="parsed"))
        c = hc.composition
        out.append(GroundingMatch(field="mechanism", written=line, grounded=c.mechanism, method="composed",
                                  alternatives=[x for x in (c.kind, c.condition, c.place, c.fix) if x]))
        out.append(GroundingMatch(field="hazard_class", written=line, grounded=hc.id, method="composed"))
        out += [
            GroundingMatch(field="scenario.placement", written=line, grounded=placement.key,
                           method="parsed" if placement_said else "class_default"),
            GroundingMatch(field="scenario.room", written=line, grounded=room, method="normalised" if room_said else "class_default"),
            GroundingMatch(field="target_asset", written=line, grounded=target,
                           method="normalised" if target in mentioned else "class_default"),
        ]
        if container is not None:
            out.append(GroundingMatch(field="scenario.container", written=line, grounded=container,
                                      method="normalised" if container in mentioned else "class_default"))
        return out


def tasks_from_lines(lines: list[str], kb: KnowledgeBase, *, seed: int = 0) -> tuple[list[TaskProposal], dict[str, str]]:
    """One proposal per line; a line that states no buildable hazard fails alone (``line<N>``: reason)."""
    tg = TextGrounder(kb, seed=seed)
    tasks: list[TaskProposal] = []
    errors: dict[str, str] = {}
    for n, line in enumerate(lines, start=1):
        try:
            tasks.append(tg.proposal(line, len(tasks) + 1))
        except ValueError as exc:
            errors[f"line{n}"] = f"'{line[:60]}': {exc}"
    return tasks, errors
