"""The brainstorming ablation: plain vs. role-play vs. full group brainstorming, measured on text.

Protocol (the paper's, configurable): draw T random target assets; for every mode run the engine
``runs`` times, each run restricted to those targets and asked for ``per_run`` proposals; pool the
proposals per mode and report mean pairwise Sentence-BERT similarity (lower = more diverse) and
Self-BLEU. Each run gets its own seed, so a mode's runs differ the way repeated LLM calls would.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field

from anomalygen.brainstorm.idea_sampler import usable_targets
from anomalygen.brainstorm.knowledge_engine import KnowledgeEngine, proposal_text
from anomalygen.knowledge import load_kb
from anomalygen.rng import item_rng
from anomalygen.schema import BrainstormMode, TaskProposal


@dataclass
class AblationRow:
    mode: str
    proposals: int
    sbert_similarity: float
    self_bleu: float | None
    distinct_scenarios: int
    classes: int
    wall_s: float


@dataclass
class AblationResult:
    targets: list[str]
    rows: list[AblationRow] = field(default_factory=list)

    def as_dict(self) -> dict:
        return {"targets": self.targets, "rows": [asdict(r) for r in self.rows]}


def pick_targets(seed: int, count: int) -> list[str]:
    options = usable_targets(load_kb())
    rng = item_rng(seed, "ablation-targets")
    return [options[int(i)] for i in rng.choice(len(options), size=min(count, len(options)), replace=False)]


def generate_mode(
    mode: BrainstormMode,
    targets: list[str],
    *,
    seed: int,
    runs: int,
    per_run: int,
    agents: int = 10,
    rounds: int = 3,
    novelty_threshold: float | None = None,
    embed_fn: Callable | None = None,
) -> list[TaskProposal]:
    if novelty_threshold is None:
        from anomalygen.config import BrainstormConfig

        novelty_threshold = BrainstormConfig().novelty_threshold
    out: list[TaskProposal] = []
    for run in range(runs):
        engine = KnowledgeEngine(
            seed=seed * 100_003 + run,
            mode=mode,
            agents=agents,
            rounds=rounds,
            novelty_threshold=novelty_threshold,
            unique=True,
            targets=targets,
            embed_fn=embed_fn,
            id_offset=len(out),
        )
        out.extend(engine.run(per_run))
    return out


def measure(proposals: list[TaskProposal], *, bleu: bool = True) -> tuple[float, float | None]:
    from anomalygen.embedding import embed, mean_pairwise_similarity

    texts = [proposal_text(p.name, p.description) for p in proposals]
    sim = mean_pairwise_similarity(embed(texts))
    sb = None
    if bleu:
        try:
            from anomalygen.evaluate.selfbleu import self_bleu
        except ImportError:  # the evaluate package is optional for this measurement
            sb = None
        else:
            sb = float(self_bleu(texts))
    return float(sim), sb


def run_ablation(
    *,
    seed: int = 0,
    n_targets: int = 10,
    runs: int = 30,
    per_run: int = 10,
    agents: int = 10,
    rounds: int = 3,
    modes: tuple[BrainstormMode, ...] = (BrainstormMode.PLAIN, BrainstormMode.ROLEPLAY, BrainstormMode.BRAINSTORM),
    bleu: bool = True,
) -> AblationResult:
    targets = pick_targets(seed, n_targets)
    result = AblationResult(targets=targets)
    for mode in modes:
        started = time.perf_counter()
        props = generate_mode(BrainstormMode(mode), targets, seed=seed, runs=runs, per_run=per_run, agents=agents, rounds=rounds)
        sim, sb = measure(props, bleu=bleu)
        scenarios = {(p.hazard_class, p.scenario.hazard_object, p.scenario.placement, p.scenario.room) for p in props}
        result.rows.append(
            AblationRow(
                mode=BrainstormMode(mode).value,
                proposals=len(props),
                sbert_similarity=round(sim, 4),
                self_bleu=None if sb is None else round(sb, 4),
                distinct_scenarios=len(scenarios),
                classes=len({p.hazard_class for p in props}),
                wall_s=round(time.perf_counter() - started, 2),
            )
        )
    return result


def format_table(result: AblationResult) -> str:
    lines = [
        f"targets: {', '.join(result.targets)}",
        f"{'mode':<11} {'n':>5} {'SBERT sim':>10} {'Self-BLEU':>10} {'scenarios':>10} {'classes':>8} {'wall s':>8}",
    ]
    for r in result.rows:
        sb = "-" if r.self_bleu is None else f"{r.self_bleu:.3f}"
        lines.append(
            f"{r.mode:<11} {r.proposals:>5} {r.sbert_similarity:>10.3f} {sb:>10} {r.distinct_scenarios:>10} {r.classes:>8} {r.wall_s:>8.1f}"
        )
    return "\n".join(lines)
