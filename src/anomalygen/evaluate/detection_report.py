"""Detection figures, all against the hidden truth: ``detections_summary.json`` and the terminal table.

One score: every claim of a scene's detection is matched to the hazards of its ``truth.json``
(``evaluate/detection_scores.py``): recall, precision, F1 and false alarms over every scene, hit@k
on single-hazard scenes (the subset comparable with the paper), recall by category and by class, a
confusion table (truth class -> class claimed on that object) and every hazard missed. The old text
judge against the task description survives only as a labelled diagnostic (``text_judge``).

Computed on the evaluate side, after the robot's items: the detect stage writes detections only.
A scene whose detector failed has no claims, so it counts as a miss, never as absent.
"""

from __future__ import annotations

from collections import Counter, defaultdict
from collections.abc import Mapping, Sequence

from pydantic import Field

from anomalygen.evaluate.detection_scores import DetectionScores, claims_on, finds, score
from anomalygen.evaluate.rate import Rate
from anomalygen.runfolder import RunFolder
from anomalygen.schema import Artefact, Detection, HazardManifest, Strict, TaskProposal
from anomalygen.tables import group_table

TEXT_JUDGE_LABEL = "text judge vs task description (diagnostic)"
SUMMARY_FILE = "detections_summary.json"


def summary_path(run: RunFolder):
    return run.root / SUMMARY_FILE


class MissedHazard(Strict):
    task_id: str
    hazard_class: str
    object: str
    claims: str = Field(description="what the detection claimed in that scene, best first, or 'none'")


class TextJudgeDiagnostic(Strict):
    """hit@k of the text judge against the hidden task's words: a diagnostic, not a score."""

    label: str = TEXT_JUDGE_LABEL
    scenes: int = Field(description="scenes with a hazard judged this way")
    hit_at_k: dict[int, float] = Field(default_factory=dict)
    by_detector: dict[str, dict[int, float]] = Field(default_factory=dict)
    methods: dict[str, int] = Field(default_factory=dict, description="how the first hits were judged")


class DetectionReport(Artefact):
    detector: str = Field(description="the one detector of every scene, or 'mixed (...)' with counts")
    detectors: dict[str, int] = Field(default_factory=dict, description="detector -> scenes it produced")
    k: int
    scenes: int = Field(description="scenes with a detection")
    errors: int = 0
    overall: DetectionScores | None = Field(None, description="against the scenes' truth.json; None without any")
    per_detector: dict[str, DetectionScores] = Field(default_factory=dict)
    per_category: dict[str, dict[str, Rate]] = Field(
        default_factory=dict, description="category -> hazard class -> truth hazards (n) and those found (successes)")
    confusion: dict[str, dict[str, int]] = Field(
        default_factory=dict, description="truth class -> class first claimed on its object ('none') -> count")
    misses: list[MissedHazard] = Field(default_factory=list)
    missing_scenes: list[str] = Field(default_factory=list, description="tasks without a detection record")
    unjudged_scenes: list[str] = Field(default_factory=list, description="detections whose scene has no truth.json")
    text_judge: TextJudgeDiagnostic | None = None

    def per_category_found(self) -> dict[str, Rate]:
        out: dict[str, Rate] = {}
        for cat, classes in self.per_category.items():
            out[cat] = Rate(n=sum(f.n for f in classes.values()), successes=sum(f.successes for f in classes.values()))
        return out


def detector_label(counts: dict[str, int]) -> str:
    """'rules', 'llm', or 'mixed (llm 6, rules 14)': a run that fell back on another detector for some
    scenes is never labelled by the one it only partly used."""
    if len(counts) == 1:
        return next(iter(counts))
    return "mixed (" + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())) + ")" if counts else "none"


def summarise(detections: Sequence[Detection], tasks: Sequence[TaskProposal], manifests: Mapping[str, HazardManifest],
              k: int, *, category_of: Mapping[str, str] | None = None) -> DetectionReport:
    """The report over ``detections`` scored against ``manifests`` (task id -> truth).

    ``category_of`` maps a hazard class to its category (the knowledge base's); unknown classes
    are grouped under 'unknown'."""
    by_task = {t.id: t for t in tasks}
    dets = [d for d in detections if d.task_id in by_task] if by_task else list(detections)
    k = max([k, *(len(d.hypotheses) for d in dets)])
    judged = [d for d in dets if d.task_id in manifests]
    per_cat: dict[str, dict[str, Rate]] = defaultdict(dict)
    confusion: dict[str, Counter] = defaultdict(Counter)
    misses: list[MissedHazard] = []
    for d in judged:
        hyps = sorted(d.hypotheses, key=lambda h: h.rank)
        for z in manifests[d.task_id].hazards:
            cat = (category_of or {}).get(z.hazard_class, "unknown")
            cell = per_cat[cat].setdefault(z.hazard_class, Rate())
            cell.n += 1
            hit = finds(hyps, z)
            cell.successes += int(hit)
            on_object = claims_on(hyps, z)
            confusion[z.hazard_class][(on_object[0].hazard_class or "free_text") if on_object else "none"] += 1
            if not hit:
                said = ", ".join(f"{h.target_object}/{h.hazard_class or 'free text'}" for h in hyps[:3]) or "none"
                misses.append(MissedHazard(task_id=d.task_id, hazard_class=z.hazard_class, object=z.object,
                                           claims=f"detector failed: {d.error}" if d.error else said))
    used = Counter(d.detector for d in dets)
    by_detector: dict[str, list[Detection]] = defaultdict(list)
    for d in judged:
        by_detector[d.detector].append(d)
    have = {d.task_id for d in dets}
    return DetectionReport(
        detector=detector_label(used),
        detectors=dict(sorted(used.items())),
        k=k,
        scenes=len(dets),
        errors=sum(1 for d in dets if d.error),
        overall=score(judged, manifests, k) if judged else None,
        per_detector={name: score(ds, manifests, k) for name, ds in sorted(by_detector.items())},
        per_category={c: dict(sorted(v.items())) for c, v in sorted(per_cat.items())},
        confusion={c: dict(sorted(cnt.items())) for c, cnt in sorted(confusion.items())},
        misses=misses,
        missing_scenes=sorted(t.id for t in tasks if t.id not in have),
        unjudged_scenes=sorted(d.task_id for d in dets if d.task_id not in manifests),
    )


def print_report(report: DetectionReport, *, console=None, max_misses: int = 20) -> None:
    """The summary on stderr (rich): scores against the truth, recall by category with each class
    under its own category, the misses, and the text judge's diagnostic labelled as such."""
    from rich.console import Console
    from rich.markup import escape

    console = console or Console(stderr=True)
    sc = report.overall
    title = f"detection against the truth ({report.detector}, {report.scenes} scenes, {report.errors} failed)"
    if sc is None:
        console.print(f"[bold]{title}[/bold]: no scene has a truth.json, nothing to score against", highlight=False)
    else:
        alarms = "n/a (no hazard-free scene)" if sc.false_alarm_rate is None else (
            f"{sc.false_alarm_rate:.2f} of {sc.hazard_free_scenes} hazard-free scenes")
        hits = ", ".join(f"hit@{j} {v:.2f}" for j, v in sorted(sc.hit_at_k.items()))
        console.print(f"[bold]{title}[/bold]\n  recall {sc.recall:.3f} ({sc.found}/{sc.hazards} hazards), precision "
                      f"{sc.precision:.3f} ({sc.true_claims}/{sc.claims} claims), F1 {sc.f1:.3f}; false alarms {alarms}\n"
                      f"  on the {sc.single_hazard_scenes} single-hazard scenes: {hits}", highlight=False)
        rows = {cat: [(cls, [str(f.n), str(f.successes), f"{f.rate:.2f}"]) for cls, f in classes.items()]
                for cat, classes in report.per_category.items()}
        totals = {cat: [str(f.n), str(f.successes), f"{f.rate:.2f}"] for cat, f in report.per_category_found().items()}
        console.print(group_table("recall by category and class (truth hazards)", ["hazards", "found", "recall"],
                                  rows, totals))
        off = [(t, p, n) for t, row in report.confusion.items() for p, n in row.items() if p != t]
        if off:
            console.print("[bold]confusions[/bold] (truth class -> class claimed on that object, count): "
                          + escape(", ".join(f"{t} -> {p} x{n}" for t, p, n in sorted(off, key=lambda x: -x[2]))),
                          highlight=False)
        if report.misses:
            console.print(f"[bold]hazards missed[/bold] ({len(report.misses)}):")
            for m in report.misses[:max_misses]:
                console.print(escape(f"  {m.task_id} [{m.hazard_class}] {m.object}; claimed: {m.claims}"),
                              highlight=False)
            if len(report.misses) > max_misses:
                console.print(f"  ... {len(report.misses) - max_misses} more in {SUMMARY_FILE}")
    if report.text_judge is not None and report.text_judge.scenes:
        tj = report.text_judge
        console.print(f"[dim]{tj.label}: " + ", ".join(f"hit@{j} {v:.2f}" for j, v in sorted(tj.hit_at_k.items()))
                      + f" over {tj.scenes} scenes — not a score[/dim]", highlight=False)
    if report.missing_scenes:
        console.print(f"[yellow]{len(report.missing_scenes)} task(s) have no detection (scene not built or failed)[/yellow]")
    if report.unjudged_scenes:
        console.print(f"[yellow]{len(report.unjudged_scenes)} detection(s) have no truth.json to score against[/yellow]")
