"""LLM group brainstorming (the paper's method): N role-playing agents, R rounds, any N and R.

Round 1: each agent is given a random target asset and proposes scenarios around it from its role's
point of view. Round r >= 2: each agent is shown every *other* agent's round r-1 proposals, told it
is in a collaborative session, and asked to build on them (citing what it builds on).

Each request asks for one proposal (``LLMProposal``), with ``max_tokens`` sized from that schema:
several proposals per reply truncated on real models. Every name in a reply is grounded first
(``knowledge/grounding.py``: spelling, aliases, Sentence-BERT retrieval), and only what even retrieval
cannot place goes back to the model with the problems listed. A failure costs one proposal, never the
batch.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

from pydantic import ValidationError

from anomalygen.brainstorm.ground_names import ground_llm_names
from anomalygen.brainstorm.idea import ASPECTS, Idea, Texts, build_proposal, task_id
from anomalygen.brainstorm.knowledge_engine import agent_roles, split_quota
from anomalygen.brainstorm.llm_reply import LLMProposal
from anomalygen.brainstorm.validate import proposal_problems
from anomalygen.knowledge import RECIPE_ARGS, ROOMS, KnowledgeBase, load_kb
from anomalygen.knowledge.grounding import GROUNDED_RELATIONS, PLACEMENT_TEXTS, NameGrounder, shared_grounder
from anomalygen.knowledge.predicates import PREDICATES
from anomalygen.llm.schema_tools import reply_token_budget
from anomalygen.rng import item_rng
from anomalygen.schema import (
    ArticulationUse,
    AuxiliaryItem,
    BrainstormMode,
    Engine,
    Placement,
    TaskProposal,
    format_validation_error,
)

ROBOT_LIMITS = (
    "The robot is a Franka Panda arm on a mobile base with a suction gripper. It can pick up and place "
    "rigid objects, push and slide them, open and close doors, drawers, lids and windows, and turn knobs "
    "and switches. It cannot assemble or take apart anything, and it cannot clean: no wiping, mopping, "
    "sweeping or washing. Every task must be solvable with those skills."
)
#: Stands in for a placement the grounder could not read, so the rest of the proposal is still checked
#: (the proposal itself goes back for repair: the grounding problem names the written placement).
UNGROUNDED_PLACEMENT = Placement(relation="on", support="floor")


@dataclass
class Shown:
    """A proposal as the other agents see it in the next round."""

    id: str
    role: str | None
    name: str
    description: str


@dataclass
class LLMEngine:
    client: object
    kb: KnowledgeBase
    seed: int = 0
    mode: BrainstormMode = BrainstormMode.BRAINSTORM
    agents: int = 10
    rounds: int = 3
    repair_retries: int = 2
    errors: dict[str, str] = field(default_factory=dict)
    accepted: list[TaskProposal] = field(default_factory=list)
    grounder: NameGrounder | None = None
    new_classes: list = field(default_factory=list)  # classes the model proposed (validated), for the run folder

    def __post_init__(self) -> None:
        from anomalygen.brainstorm.free_text import TextGrounder

        if self.grounder is None:
            self.grounder = NameGrounder(self.kb)
        # reads the hazard a proposal's text states, as for a user's line (objects known, assets or not)
        self.reader = TextGrounder(self.kb, self.grounder, seed=self.seed, catalogue=set(self.kb.objects))

    @property
    def token_cap(self) -> int | None:
        """The configured ``llm.max_tokens``: an upper bound on the schema-sized budget."""
        return getattr(getattr(self.client, "config", None), "max_tokens", None)

    @classmethod
    def from_settings(cls, settings) -> LLMEngine:
        from anomalygen.llm import get_client

        cfg = settings.brainstorm
        return cls(
            client=get_client(settings.llm),
            kb=load_kb(),
            seed=settings.seed,
            mode=cfg.mode,
            agents=cfg.agents,
            rounds=cfg.rounds,
            repair_retries=settings.llm.repair_retries,
            grounder=shared_grounder(),
        )

    # ------------------------------------------------------------------ run
    def run(self, n: int) -> list[TaskProposal]:
        """``n`` proposals, one request each; rounds still show every agent the others' last round."""
        mode = BrainstormMode(self.mode)
        n_agents = 1 if mode == BrainstormMode.PLAIN else self.agents
        rounds = self.rounds if mode == BrainstormMode.BRAINSTORM else 1
        roles: list[str | None] = [None] if mode == BrainstormMode.PLAIN else agent_roles(self.kb, n_agents)
        previous: list[tuple[int, Shown]] = []
        budget = reply_token_budget(LLMProposal, cap=self.token_cap)
        for r, quota in enumerate(split_quota(n, rounds), start=1):
            shares = split_quota(quota, n_agents, offset=r - 1)
            jobs = [(i, k, share) for i, share in enumerate(shares) for k in range(share)]
            convs = [self.messages(r, i, roles[i], previous, k=k, share=share) for i, k, share in jobs]
            replies = self.client.complete_many(convs, schema=LLMProposal, max_tokens=budget)
            this_round: list[tuple[int, Shown]] = []
            for (i, k, share), conv, reply in zip(jobs, convs, replies, strict=True):
                item = f"r{r}-agent{i}" + (f"-p{k + 1}" if share > 1 else "")
                if isinstance(reply, Exception):
                    self.errors[item] = str(reply)
                    continue
                shown_ids = {s.id for a, s in previous if a != i}
                p = self._accept(reply, conv, r, roles[i], shown_ids, item, budget)
                if p is not None:
                    this_round.append((i, Shown(p.id, roles[i], p.name, p.description)))
            previous = this_round
        return list(self.accepted)

    def from_texts(self, lines: list[str]) -> list[TaskProposal]:
        """One proposal per plain description (``--tasks-text``): the model structures the line, the
        grounder resolves its names; a line that stays invalid fails alone (``line<N>``)."""
        budget = reply_token_budget(LLMProposal, cap=self.token_cap)
        convs = [
            [
                {"role": "system", "content": self.system_prompt(None)},
                {"role": "user", "content": "Write this household hazard as one structured scenario, keeping its "
                 f"objects, place and people:\n{line}"},
            ]
            for line in lines
        ]
        replies = self.client.complete_many(convs, schema=LLMProposal, max_tokens=budget)
        for n, (conv, reply) in enumerate(zip(convs, replies, strict=True), start=1):
            if isinstance(reply, Exception):
                self.errors[f"line{n}"] = str(reply)
                continue
            # the person's words stay the description (a repair may reword them: they are put back)
            self._accept(reply.model_copy(update={"description": lines[n - 1]}), conv, 1, None, set(), f"line{n}", budget,
                         line=lines[n - 1])
        return list(self.accepted)

    # ------------------------------------------------------------------ prompts
    def system_prompt(self, role: str | None) -> str:
        kb = self.kb
        classes = "\n".join(f"- {hc.id} ({hc.category.value}): {hc.name}" for hc in kb.hazard_classes.values())
        parts = []
        if role is not None:
            rp = kb.roles[role]
            parts.append(
                f"You are the {rp.name} of a household. {rp.description} You look at a home as someone who "
                f"{rp.perspective}. You are one of several household experts in a collaborative brainstorming "
                "session about hazards in the home that a robot could notice and fix on its own."
            )
        else:
            parts.append("You write household hazard scenarios that a robot could notice and fix on its own.")
        parts += [
            ROBOT_LIMITS,
            "Hazard classes (use the id, or 'other' with hazard_other):\n" + classes,
            "If no class fits, you may instead describe the hazard as new_class: preconditions and success as "
            "predicate calls over $hazard (predicates: " + ", ".join(sorted(PREDICATES)) + "), and a recipe of actions ("
            + ", ".join(RECIPE_ARGS) + ").",
            "Target categories: " + ", ".join(kb.targets),
            "Other catalogue objects: " + ", ".join(kb.household),
            "Rooms: " + ", ".join(ROOMS),
            "Placements of the hazard object: "
            + ", ".join([*PLACEMENT_TEXTS, *(f"{r}:<catalogue name>" for r in GROUNDED_RELATIONS)]),
            "Use only catalogue names, exactly as written, for target_asset, hazard_object, container and co_objects.",
        ]
        return "\n\n".join(parts)

    def messages(
        self, r: int, i: int, role: str | None, previous: list[tuple[int, Shown]], *, k: int = 0, share: int = 1
    ) -> list[dict]:
        """The request for an agent's ``k``-th proposal of round ``r`` (one proposal per request)."""
        others = [s for a, s in previous if a != i]
        if r == 1 or not others:
            rng = item_rng(self.seed, "llm-brainstorm", r, i, k)
            target = self.kb.targets[int(rng.integers(len(self.kb.targets)))]
            ask = (
                f"Round {r}. Your target object is {target}. Propose one hazard scenario in a home that "
                f"involves the {target} (as the hazard, the place to store it, or the setting)."
            )
        else:
            listing = "\n".join(f"- [{s.id}] ({s.role or 'participant'}) {s.name}: {s.description}" for s in others)
            aspect = ASPECTS[(i + k) % len(ASPECTS)]
            ask = (
                f"Round {r} of the brainstorming session. These are the other participants' proposals from "
                f"round {r - 1}:\n{listing}\n\nBuild on them: take the {aspect.replace('_', ' ')} of one of "
                "their ideas, combine it with your own perspective, and propose one new scenario that is "
                "different from all of the above. Put the ids you build on in builds_on and what you "
                "borrowed in borrowed."
            )
        if share > 1:
            ask += f" This is idea {k + 1} of {share} you write this round; give each its own angle."
        return [{"role": "system", "content": self.system_prompt(role)}, {"role": "user", "content": ask}]

    # ------------------------------------------------------------------ validation and repair
    def _accept(self, raw: LLMProposal, conv, r, role, shown_ids, item, budget, *, line: str | None = None) -> TaskProposal | None:
        """Ground and validate one proposal; what cannot be grounded without a substitute goes back."""
        proposal, problems = self._convert(raw, r, role, shown_ids)
        for _ in range(self.repair_retries):
            if not problems:
                break
            fixed = self._repair(conv, raw, problems, budget)
            if fixed is None:
                break
            raw = fixed if line is None else fixed.model_copy(update={"description": line})
            proposal, problems = self._convert(raw, r, role, shown_ids)
        if problems or proposal is None:
            self.errors[item] = "; ".join(problems)[:500]
            return None
        if proposal.name.lower() in {p.name.lower() for p in self.accepted}:
            self.errors[item] = f"duplicate of an accepted proposal named '{proposal.name}'"
            return None
        update = {"id": task_id(len(self.accepted) + 1, proposal.name)}
        if line is not None:
            update["source"] = "user_text"
        proposal = proposal.model_copy(update=update)
        self.accepted.append(proposal)
        return proposal

    def _repair(self, conv, raw: LLMProposal, problems: list[str], budget: int) -> LLMProposal | None:
        follow = conv + [
            {"role": "assistant", "content": raw.model_dump_json()},
            {
                "role": "user",
                "content": "This proposal cannot be built:\n- " + "\n- ".join(problems) + "\nUse only the catalogue "
                "names, rooms, placements and class ids listed above. Reply with the corrected proposal.",
            },
        ]
        try:
            out = self.client.complete(follow, schema=LLMProposal, max_tokens=budget)
        except Exception as exc:  # noqa: BLE001 - a failed repair fails this one proposal only
            problems.append(f"repair failed: {str(exc)[:200]}")
            return None
        return out if isinstance(out, LLMProposal) else None

    def _convert(self, raw: LLMProposal, r: int, role: str | None, shown_ids: set[str]) -> tuple[TaskProposal | None, list[str]]:
        kb = self.kb
        g = ground_llm_names(raw, self.grounder, reader=self.reader)
        if g.new_class is not None and not g.problems:  # known to every later check in this process
            kb.hazard_classes.setdefault(g.new_class.id, g.new_class)
            if g.new_class not in self.new_classes:
                self.new_classes.append(g.new_class)
        hc = kb.hazard_classes.get(g.hazard_class)
        category = hc.category if hc is not None else raw.category
        articulations = []
        if raw.articulated_part:
            obj = g.hazard_object if g.hazard_object in kb.objects else g.target_asset
            initial = raw.part_initial_state or (hc.articulation.initial_state if hc and hc.articulation else "open")
            target_state = hc.articulation.target_state if hc and hc.articulation else "closed"
            articulations.append(ArticulationUse(object=obj, part=raw.articulated_part, initial_state=initial, target_state=target_state))
        aux = [
            AuxiliaryItem(name=n, description=kb.objects[n].description if n in kb.objects else "", purpose=purpose)
            for n, purpose in [(g.hazard_object, "the hazard itself"), (g.container, "where the robot puts it")]
            + [(c, "part of the setting") for c in g.co_objects]
            if n and n != g.target_asset
        ]
        idea = Idea(
            class_id=g.hazard_class,
            target=g.target_asset,
            hazard=g.hazard_object,
            # an ungrounded placement is a problem already (g.problems): the proposal goes back
            placement=g.placement or UNGROUNDED_PLACEMENT,
            room=g.room,
            person=raw.person_at_risk,
            container=g.container,
            co_objects=tuple(g.co_objects),
            agent=role,
            round=r,
            builds_on=tuple(b for b in raw.builds_on if b in shown_ids),
            borrowed=tuple(b for b in raw.borrowed if b in ASPECTS),
        )
        texts = Texts(
            name=raw.name.strip() or "untitled",
            explanation=raw.explanation,
            description=raw.description,
            solution=raw.solution,
            success_condition=raw.success_condition,
        )
        try:
            proposal = build_proposal(
                idea,
                texts,
                id="pending",
                category=category,
                hazard_other=g.hazard_other,
                auxiliary_items=aux,
                articulations=articulations,
                engine=Engine.LLM,
                mode=BrainstormMode(self.mode),
                seed=self.seed,
                model=getattr(self.client, "model", None),
                grounding=g.matches,
            )
        except ValidationError as exc:
            return None, [format_validation_error(exc)]
        if g.called:  # a word of the lexicon: built as its kind's proxy shape, under the model's word
            proposal = proposal.model_copy(update={"scenario": proposal.scenario.model_copy(update={"called": g.called})})
        unresolved = {m.written for m in g.matches if m.grounded is None and m.method != "dropped"}
        rest = [p for p in proposal_problems(proposal, kb) if not any(f"'{w}'" in p for w in unresolved)]
        return proposal, g.problems + rest


def reply_json(proposal: dict) -> str:
    """Serialise a scripted reply (tests, examples)."""
    return json.dumps(proposal)
