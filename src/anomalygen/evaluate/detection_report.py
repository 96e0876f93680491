"""Detection figures: hit@1..k overall, per category and per class, a confusion table, and the misses.

Computed from the judged per-scene ``Detection`` records and the (hidden) tasks only, so the summary
can be re-made from a run folder at any time; the judge stage writes it to ``detections_summary.json``
with the per-hazard scores against truth.json. A scene whose detector failed counts as a miss, never
as absent, so failures cannot flatter the hit rate.
"""

from __future__ import annotations

from collections import Counter, defaultdict
from collections.abc import Sequence

from pydantic import Field

from anomalygen.referee.score import DetectionScores
from anomalygen.schema import Artefact, Detection, Strict, TaskProposal

SUMMARY_FILE = "detections_summary.json"


def summary_path(run):
    """``detections_summary.json`` of a run folder (written by the judge stage)."""
    return run.root / SUMMARY_FILE


class HitRates(Strict):
    n: int
    hits: dict[int, int] = Field(description="k -> scenes with a hit within the top k")
    rate: dict[int, float] = Field(description="k -> hit@k")


class Miss(Strict):
    task_id: str
    hazard_class: str
    category: str
    top1: str = Field(description="object/class of the first hypothesis, or 'none'")
    reason: str


class DetectionReport(Artefact):
    detector: str = Field(description="the one detector of every scene, or 'mixed (...)' with counts")
    detectors: dict[str, int] = Field(default_factory=dict, description="detector -> scenes it produced")
    k: int
    scenes: int
    errors: int = 0
    overall: HitRates
    per_category: dict[str, HitRates]
    per_class: dict[str, HitRates]
    confusion: dict[str, dict[str, int]] = Field(description="true class -> top-1 predicted class -> count")
    misses: list[Miss]
    judge_methods: dict[str, int] = Field(default_factory=dict, description="how the first hits were judged")
    missing_scenes: list[str] = Field(default_factory=list, description="tasks without a detection record")
    scores: DetectionScores | None = Field(None, description="per-hazard scores against the scenes' truth.json")


def detector_label(counts: dict[str, int]) -> str:
    """'rules', 'llm', or 'mixed (llm 6, rules 14)': a run that fell back on another detector for some
    scenes is never labelled by the one it only partly used."""
    if len(counts) == 1:
        return next(iter(counts))
    return "mixed (" + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())) + ")" if counts else "none"


def _rates(dets: Sequence[Detection], k: int) -> HitRates:
    n = len(dets)
    hits = {j: sum(1 for d in dets if d.hit_rank is not None and d.hit_rank <= j) for j in range(1, k + 1)}
    return HitRates(n=n, hits=hits, rate={j: round(h / n, 4) if n else 0.0 for j, h in hits.items()})


def summarise(detections: Sequence[Detection], tasks: Sequence[TaskProposal], k: int) -> DetectionReport:
    """hit@k over the scenes that hold a hazard (hazard-free scenes are scored as false alarms instead)."""
    by_task = {t.id: t for t in tasks}
    have = {d.task_id for d in detections if d.task_id in by_task}
    dets = [d for d in detections if d.task_id in by_task and not d.hazard_free]
    cat_groups: dict[str, list[Detection]] = defaultdict(list)
    cls_groups: dict[str, list[Detection]] = defaultdict(list)
    confusion: dict[str, Counter] = defaultdict(Counter)
    misses: list[Miss] = []
    methods: Counter = Counter()
    for d in dets:
        t = by_task[d.task_id]
        cat_groups[str(t.category)].append(d)
        cls_groups[t.hazard_class].append(d)
        top = d.hypotheses[0] if d.hypotheses else None
        confusion[t.hazard_class][(top.hazard_class or "free_text") if top else "none"] += 1
        if d.hit_rank is not None:
            first = next((j for j in d.judgements if j.rank == d.hit_rank), None)
            methods[first.method if first else "unknown"] += 1
        if d.hit_rank is None or d.hit_rank > 1:
            reason = d.error and f"detector failed: {d.error}" or d.miss_reason or "not hit at rank 1"
            if d.hit_rank is not None:
                reason = f"hit only at rank {d.hit_rank}; rank 1: {d.judgements[0].reason if d.judgements else '?'}"
            misses.append(
                Miss(
                    task_id=d.task_id,
                    hazard_class=t.hazard_class,
                    category=str(t.category),
                    top1=f"{top.target_object}/{top.hazard_class or 'free text'}" if top else "none",
                    reason=reason,
                )
            )
    used = Counter(d.detector for d in dets)
    return DetectionReport(
        detector=detector_label(used),
        detectors=dict(sorted(used.items())),
        k=k,
        scenes=len(dets),
        errors=sum(1 for d in dets if d.error),
        overall=_rates(dets, k),
        per_category={c: _rates(g, k) for c, g in sorted(cat_groups.items())},
        per_class={c: _rates(g, k) for c, g in sorted(cls_groups.items())},
        confusion={c: dict(sorted(cnt.items())) for c, cnt in sorted(confusion.items())},
        misses=misses,
        judge_methods=dict(sorted(methods.items())),
        missing_scenes=sorted(t.id for t in tasks if t.id not in have),
    )


def print_report(report: DetectionReport, *, console=None, max_misses: int = 20) -> None:
    """The summary table on stderr (rich): hit@k by category and class, then the misses."""
    from rich.console import Console
    from rich.table import Table

    console = console or Console(stderr=True)
    ks = list(range(1, report.k + 1))
    table = Table(title=f"detection ({report.detector}, {report.scenes} scenes, {report.errors} failed)")
    table.add_column("group")
    table.add_column("n", justify="right")
    for j in ks:
        table.add_column(f"hit@{j}", justify="right")

    def row(name: str, r: HitRates, style: str | None = None) -> None:
        table.add_row(name, str(r.n), *(f"{r.rate[j]:.3f}" for j in ks), style=style)

    row("overall", report.overall, "bold")
    for name, r in report.per_category.items():
        row(name, r, "cyan")
    for name, r in report.per_class.items():
        row(f"  {name}", r)
    console.print(table)
    off = [(t, p, n) for t, row in report.confusion.items() for p, n in row.items() if p != t]
    if off:
        console.print("[bold]confusions[/bold] (true class -> top-1 class, count): "
                      + ", ".join(f"{t} -> {p} x{n}" for t, p, n in sorted(off, key=lambda x: -x[2])), highlight=False)
    if report.misses:
        console.print(f"[bold]misses at rank 1[/bold] ({len(report.misses)}):")
        for m in report.misses[:max_misses]:
            console.print(f"  {m.task_id} [{m.hazard_class}] top-1 {m.top1}: {m.reason}", highlight=False)
        if len(report.misses) > max_misses:
            console.print(f"  ... {len(report.misses) - max_misses} more in detections_summary.json")
    if report.scores is not None:
        sc = report.scores
        alarms = "n/a (no hazard-free scene)" if sc.false_alarm_rate is None else f"{sc.false_alarm_rate:.3f}"
        console.print(f"[bold]against truth.json[/bold]: {sc.hazards} hazards in {sc.scenes} scenes; "
                      f"recall {sc.recall:.3f} ({sc.found}), precision {sc.precision:.3f} "
                      f"({sc.true_claims}/{sc.claims} claims), F1 {sc.f1:.3f}; false alarms {alarms}", highlight=False)
    if report.missing_scenes:
        console.print(f"[yellow]{len(report.missing_scenes)} task(s) have no detection (scene not built or failed)[/yellow]")
