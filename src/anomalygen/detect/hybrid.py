"""The hybrid detector: the rules propose, the LLM ranks and explains.

Rules are precise about *what* fires (every candidate is a knowledge-base class on a real object)
but rank only by fixed severities; an LLM is better at judging which of several hits matters most
in this particular room. So the LLM sees the observation and a numbered candidate list and returns
an order with its own wording of problem and fix; it cannot invent objects or classes. If the LLM
fails, the rule order stands and every hypothesis says so.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, create_model

from anomalygen.detect import rules
from anomalygen.detect.asking import AskingDetector
from anomalygen.detect.observation import observation_text
from anomalygen.schema import Hypothesis, SceneGraph

#: How many rule candidates the LLM gets to choose from (at least k).
POOL = 6

SYSTEM_PROMPT = (
    "You are the safety sense of a household robot. A rule engine has listed possible hazards in a room; "
    "some are real and serious, some matter less here. Order the candidates from most to least important "
    "for the robot to fix now, and say in your own words what the problem is and what to do."
)


def reply_schema(n: int, k: int) -> type[BaseModel]:
    pick = create_model(
        "RankedCandidate",
        __config__=ConfigDict(extra="forbid"),
        candidate=(int, Field(ge=1, le=n, description="number of the candidate in the list")),
        problem=(str, Field(min_length=3, max_length=400)),
        solution=(str, Field(min_length=3, max_length=400)),
    )
    return create_model(
        "CandidateRanking",
        __config__=ConfigDict(extra="forbid"),
        ranking=(list[pick], Field(min_length=1, max_length=min(n, k))),
    )


def user_prompt(graph: SceneGraph, cands: list[rules.Candidate], k: int) -> str:
    listing = "\n".join(
        f"{i}. {c.hazard_class} on {c.object}: {c.problem} (evidence: {c.explanation})" for i, c in enumerate(cands, 1)
    )
    return f"{observation_text(graph)}\n\nCandidates:\n{listing}\n\nReturn the {min(k, len(cands))} most important, best first."


class HybridDetector(AskingDetector):
    name = "hybrid"

    def __init__(self, client, kb=None, *, temperature: float | None = 0.0, seed: int | None = 0):
        super().__init__(client, kb, temperature=temperature, seed=seed)
        self.fell_back: str | None = None  # the reason of the last fallback, for the stage's summary

    def detect(self, graph: SceneGraph, k: int) -> list[Hypothesis]:
        from anomalygen.llm import LLMItemError

        self.fell_back = None
        cands = rules.rank(rules.candidates(graph, self.kb), max(k, POOL))
        if not cands:
            return []
        try:
            reply = self.ask(SYSTEM_PROMPT, user_prompt(graph, cands, k), reply_schema(len(cands), k))
        except LLMItemError as exc:
            self.fell_back = str(exc)
            hyps = rules.to_hypotheses(cands[:k])
            for h in hyps:
                h.explanation = f"LLM ranking failed ({exc}); rule order kept. {h.explanation}"
            return hyps
        order: list[tuple[rules.Candidate, str, str, str]] = []
        used: set[int] = set()
        for pick in reply.ranking:
            if pick.candidate in used:
                continue
            used.add(pick.candidate)
            order.append((cands[pick.candidate - 1], pick.problem, pick.solution, f"ranked by LLM ({self.client.model})"))
        for i, c in enumerate(cands, 1):  # the LLM may list fewer than k: fill in rule order
            if len(order) >= k:
                break
            if i not in used:
                order.append((c, c.problem, c.solution, "not ranked by the LLM; rule order"))
        return [
            Hypothesis(
                rank=r,
                problem=problem,
                solution=solution,
                target_object=c.object,
                hazard_class=c.hazard_class,
                score=c.score,
                explanation=f"{how}; {c.explanation}",
            )
            for r, (c, problem, solution, how) in enumerate(order[:k], start=1)
        ]
