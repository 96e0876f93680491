"""The offline brainstorming engine: role-playing agents, recombination rounds, a novelty filter.

It mirrors the paper's group brainstorming without an LLM. Round 1: every agent picks a target
asset by its interests and grounds a scenario around it. Rounds >= 2: every agent reads the other
agents' proposals from the previous round and recombines them (borrowing a mechanism, a location,
co-objects or a person at risk) with its own interests. A Sentence-BERT novelty filter rejects
near-duplicates of what the group has already proposed.

Ablation modes (same realiser for all, so differences come from the method, not the wording code):
- ``plain``: one role-less generator, one pass; uniform choices, no people or co-objects.
- ``roleplay``: the role agents, one pass, no rounds and no novelty filter.
- ``brainstorm``: role agents, R rounds of recombination, novelty filter.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from anomalygen.brainstorm.idea import Idea, Texts, task_id, to_proposal
from anomalygen.brainstorm.idea_sampler import IdeaSampler
from anomalygen.brainstorm.realise import realise
from anomalygen.knowledge import KnowledgeBase, load_kb
from anomalygen.rng import item_rng
from anomalygen.schema import BrainstormMode, Engine, Placement, TaskProposal

#: The most of a brainstorm's tasks one room may hold; kitchens otherwise take nearly half (issue 39).
ROOM_SHARE = 0.30
#: Below this many tasks a room cap would only starve small draws (a 3-task demo may be all kitchen).
MIN_N_FOR_ROOM_CAP = 20

EmbedFn = Callable[[list[str]], np.ndarray]


def proposal_text(name: str, description: str) -> str:
    """The text diversity is measured on (as in the paper: name and description together)."""
    return f"{name}. {description}"


def agent_roles(kb: KnowledgeBase, n_agents: int) -> list[str]:
    """Role ids for N agents: the ten roles in order, cycling when N > 10."""
    roles = list(kb.roles)
    return [roles[i % len(roles)] for i in range(n_agents)]


def split_quota(total: int, parts: int, offset: int = 0) -> list[int]:
    base, extra = divmod(total, parts)
    return [base + (1 if (i - offset) % parts < extra else 0) for i in range(parts)]


@dataclass
class Accepted:
    index: int
    id: str
    idea: Idea
    texts: Texts
    vector: np.ndarray | None


class KnowledgeEngine:
    """Generates TaskProposals from the knowledge base; deterministic for a seed."""

    def __init__(
        self,
        *,
        seed: int = 0,
        mode: BrainstormMode = BrainstormMode.BRAINSTORM,
        agents: int = 10,
        rounds: int = 3,
        novelty_threshold: float = 0.85,
        unique: bool = True,
        targets: list[str] | None = None,
        embed_fn: EmbedFn | None = None,
        kb: KnowledgeBase | None = None,
        id_offset: int = 0,
        max_extra_rounds: int = 3,
    ):
        self.kb = kb or load_kb()
        self.seed = seed
        self.mode = BrainstormMode(mode)
        self.n_agents = 1 if self.mode == BrainstormMode.PLAIN else agents
        self.rounds = rounds if self.mode == BrainstormMode.BRAINSTORM else 1
        self.threshold = novelty_threshold
        self.use_novelty = self.mode == BrainstormMode.BRAINSTORM
        self.unique = unique or self.mode == BrainstormMode.BRAINSTORM
        self.targets = targets
        self.id_offset = id_offset
        self.max_extra_rounds = max_extra_rounds if self.mode == BrainstormMode.BRAINSTORM else 3
        if embed_fn is None and self.use_novelty:
            from anomalygen.embedding import embed

            embed_fn = embed
        self.embed_fn = embed_fn
        roles = agent_roles(self.kb, self.n_agents) if self.mode != BrainstormMode.PLAIN else [None]
        self.agents: list[str | None] = roles
        rich = self.mode != BrainstormMode.PLAIN
        self.samplers = [
            IdeaSampler(self.kb, self.kb.roles[r] if r else None, targets=targets, rich=rich) for r in roles
        ]
        self.accepted: list[Accepted] = []
        self.rejected_near_duplicates = 0
        self.rejected_same_scenario = 0
        self.rejected_room_full = 0
        self.room_cap: int | None = None
        #: set once every composed scene is taken: then a scene may recur for another person at risk
        self.told_apart = False

    # ------------------------------------------------------------------ public
    def run(self, n: int) -> list[TaskProposal]:
        # no room holds more than ROOM_SHARE of the tasks (issue 39): a kitchen-heavy draw is redrawn.
        # Only over the open catalogue: a run given a few targets (a fridge, a stove) may need one room.
        self.room_cap = (max(1, int(ROOM_SHARE * n)) if self.mode == BrainstormMode.BRAINSTORM and n >= MIN_N_FOR_ROOM_CAP
                         and self.targets is None else None)
        quotas = split_quota(n, self.rounds)
        carry = 0
        r = 0
        while True:
            r += 1
            want = (quotas[r - 1] if r <= self.rounds else 0) + carry
            if want <= 0 and r >= self.rounds:
                break
            if r > self.rounds + self.max_extra_rounds:
                break
            previous = [a for a in self.accepted if a.idea.round == r - 1]
            got = self._round(r, want, previous)
            carry = want - got
            if r >= self.rounds and carry <= 0:
                break
        if self.unique and len(self.accepted) < n and not self.told_apart:
            # the rounds ran out (every composed scene taken, or the room cap full): the rest may repeat
            # a scene for another person at risk, in any room, rather than return fewer tasks than asked
            self.told_apart = True
            self.room_cap = None
            for _extra in range(self.max_extra_rounds + 1):
                previous = [a for a in self.accepted if a.idea.round == r]
                r += 1
                self._round(r, n - len(self.accepted), previous)
                if len(self.accepted) >= n:
                    break
        return [self._proposal(a) for a in self.accepted]

    def _key(self, idea: Idea) -> tuple:
        return (*idea.key(), idea.person) if self.told_apart else idea.key()

    # ------------------------------------------------------------------ rounds
    def _round(self, r: int, want: int, previous: list[Accepted]) -> int:
        """One round: every agent proposes its share; candidates are embedded in one batch per attempt.

        Agents in a round do not see each other's same-round ideas (as in the paper), so all of a
        round's candidates can be drafted first and filtered afterwards, in agent order.
        """
        needs = split_quota(want, self.n_agents, offset=r - 1)
        seen = self._usage_counts() if self.mode == BrainstormMode.BRAINSTORM else {}
        got_total = 0
        for attempt in range(8):
            drafts: list[tuple[int, Idea, Texts]] = []
            for i, need in enumerate(needs):
                if need <= 0:
                    continue
                sampler = self.samplers[i]
                sampler.seen = seen
                others = [(a.id, a.idea) for a in previous if a.idea.agent_index != i]
                rng = item_rng(self.seed, "brainstorm", self.mode.value, r, i, attempt)
                for _ in range(need + (1 if attempt == 0 else 2)):
                    idea = None
                    if r >= 2 and others:
                        idea = sampler.recombine(rng, others, agent=self.agents[i], agent_index=i, round_=r)
                    if idea is None:
                        idea = sampler.fresh(rng, agent=self.agents[i], agent_index=i, round_=r)
                    # wording draws from its own stream, so changing phrase banks never changes scenarios
                    words = item_rng(self.seed, "realise", self.mode.value, r, i, attempt, len(drafts))
                    texts = realise(idea, self.kb, words)
                    drafts.append((i, idea, texts))
            drafts = self._prefilter(drafts, needs)
            if not drafts:
                if all(n <= 0 for n in needs):
                    break
                continue
            vectors = self._embed([t for _, _, t in drafts])
            for k, (i, idea, texts) in enumerate(drafts):
                if needs[i] <= 0:
                    continue
                if self._accept(idea, texts, None if vectors is None else vectors[k]):
                    needs[i] -= 1
                    got_total += 1
            if attempt >= 2:  # an agent that keeps repeating the group hands its share on
                leftover = sum(n for n in needs if n > 0)
                needs = split_quota(leftover, self.n_agents, offset=r + attempt) if leftover else needs
        return got_total

    def _prefilter(self, drafts: list[tuple[int, Idea, Texts]], needs: list[int]) -> list[tuple[int, Idea, Texts]]:
        """Drop drafts that repeat a scenario or name before paying for their embeddings.

        Keeps at most need + 1 drafts per agent, so the costly Sentence-BERT pass sees few spares.
        """
        if not self.unique:
            return drafts
        keys = {self._key(a.idea) for a in self.accepted}
        names = {a.texts.name.lower() for a in self.accepted}
        kept: list[tuple[int, Idea, Texts]] = []
        per_agent: dict[int, int] = {}
        for i, idea, texts in drafts:
            if self._key(idea) in keys or (texts.name.lower() in names and not self.told_apart):
                self.rejected_same_scenario += 1
                continue
            if per_agent.get(i, 0) >= needs[i] + 1:
                continue
            keys.add(self._key(idea))
            names.add(texts.name.lower())
            per_agent[i] = per_agent.get(i, 0) + 1
            kept.append((i, idea, texts))
        return kept

    def _usage_counts(self) -> dict[str | Placement, int]:
        """What the group has proposed so far (agents in a session see the shared pool)."""
        counts: dict[str | Placement, int] = {}
        for a in self.accepted:
            i = a.idea
            for key in {i.class_id, i.hazard, i.target, i.room, i.placement}:
                counts[key] = counts.get(key, 0) + 1
        return counts

    def _embed(self, texts: list[Texts]) -> np.ndarray | None:
        if not self.use_novelty or self.embed_fn is None:
            return None
        return np.asarray(self.embed_fn([proposal_text(t.name, t.description) for t in texts]), dtype=np.float32)

    def _accept(self, idea: Idea, texts: Texts, vec: np.ndarray | None) -> bool:
        if self.unique:
            keys = {self._key(a.idea) for a in self.accepted}
            names = {a.texts.name.lower() for a in self.accepted}
            if self._key(idea) in keys or (texts.name.lower() in names and not self.told_apart):
                self.rejected_same_scenario += 1
                return False
        if self.room_cap is not None and sum(a.idea.room == idea.room for a in self.accepted) >= self.room_cap:
            self.rejected_room_full += 1
            return False
        # a scene told apart by its person says the same situation in nearly the same words by design
        if vec is not None and self.accepted and not self.told_apart:
            pool = np.stack([a.vector for a in self.accepted if a.vector is not None])
            if float((pool @ vec).max()) >= self.threshold:
                self.rejected_near_duplicates += 1
                return False
        index = self.id_offset + len(self.accepted) + 1
        self.accepted.append(Accepted(index=index, id=task_id(index, texts.name), idea=idea, texts=texts, vector=vec))
        return True

    def _proposal(self, a: Accepted) -> TaskProposal:
        return to_proposal(a.idea, a.texts, a.index, self.kb, engine=Engine.KNOWLEDGE, mode=self.mode, seed=self.seed)


def generate(n: int, **kwargs) -> list[TaskProposal]:
    """Convenience: ``KnowledgeEngine(**kwargs).run(n)``."""
    return KnowledgeEngine(**kwargs).run(n)
