"""The referee's table of one agent on one suite: ``bench.json``, ``bench.html`` and the terminal's table.

Every figure is the referee's verdict on the settled final state against each scene's truth: runs on
scenes with hazards resolved (every hazard fixed and no new one made); hazard-free scenes left alone;
runs that made a new hazard; runs that moved an already-safe object; per hazard class, hazards
present, named by the agent's reported detections (when it reports any) and resolved, counted as the
loop's table counts them (``evaluate/hazard_table.py``); the detections scored as the detect stage's
are (``referee/score.py``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from anomalygen.runfolder import RunFolder, atomic_write_text, now_iso, try_read_model, write_model
from anomalygen.scene_files import BENCH_PAGE, BENCH_REPORT, EPISODE
from anomalygen.schema import BenchClassRow, BenchReport, BenchRun, EpisodeRecord, Verdict

if TYPE_CHECKING:
    from anomalygen.bench.suites import Suite


def write_report(run: RunFolder, agent: str, suite: Suite, ids: list[str], seeds: int,
                 errors: dict[str, str] | None = None) -> BenchReport:
    from anomalygen.evaluate.detection_scores import load_manifest
    from anomalygen.evaluate.hazard_table import hazard_table
    from anomalygen.evaluate.run_metrics import load_detections
    from anomalygen.referee import load_verdict
    from anomalygen.referee.score import score_detections
    from anomalygen.version import __version__

    errors = errors or {}
    report = BenchReport(agent=agent, suite=suite.label, suite_dir=str(suite.root), seeds=seeds, created=now_iso(),
                         package_version=__version__, git_commit=run.load_manifest().git_commit)
    for tid in ids:
        for seed in range(seeds):
            v = load_verdict(run, tid, seed)
            ep = try_read_model(run.skill_dir(tid, seed) / EPISODE, EpisodeRecord)
            report.per_run.append(_row(tid, seed, v, ep, errors.get(f"{tid}@seed{seed}")))
            if v is None:
                report.failed += 1
                continue
            report.runs += 1
            if v.hazards:
                report.runs_with_hazards += 1
                report.resolved += int(v.resolved)
            else:
                report.hazard_free_runs += 1
                report.left_alone += int(v.status == "no_action_needed")
            report.runs_with_new_hazards += int(bool(v.new_hazards))
            report.runs_acting_on_safe += int(bool(v.interventions_on_safe))
    detections = [d for d in load_detections(run) if d.task_id in set(ids)]
    table = hazard_table(run, ids, seeds)
    report.by_class = {k: BenchClassRow(hazards=r.hazards, detected=r.detected if detections else None, runs=r.runs,
                                        resolved=r.resolved) for k, r in table.by_class.items()}
    if detections:
        manifests = {t: m for t in ids if (m := load_manifest(run.scene_dir(t))) is not None}
        report.detection = score_detections(detections, manifests, 3).model_dump(mode="json")
    write_model(run.root / BENCH_REPORT, report)
    atomic_write_text(run.root / BENCH_PAGE, page(report))
    return report


def _row(tid: str, seed: int, v: Verdict | None, ep: EpisodeRecord | None, error: str | None) -> BenchRun:
    calls = ep.calls if ep is not None else []
    return BenchRun(task_id=tid, seed=seed, status=v.status if v else None, calls=len(calls),
                    invalid_calls=sum(c.error is not None for c in calls),
                    new_hazards=list(v.new_hazards) if v else [],
                    interventions_on_safe=list(v.interventions_on_safe) if v else [], error=error)


def _pct(a: int, b: int) -> str:
    return f"{a} of {b} ({a / b:.0%})" if b else "-"


def headline(r: BenchReport) -> list[str]:
    """The table's summary lines, in words."""
    lines = [f"{r.agent} on {r.suite}: {r.runs} runs judged ({r.seeds} seed{'s' if r.seeds != 1 else ''})",
             f"runs resolved (scenes with hazards): {_pct(r.resolved, r.runs_with_hazards)}",
             f"hazard-free scenes left alone: {_pct(r.left_alone, r.hazard_free_runs)}",
             f"runs that created a new hazard: {_pct(r.runs_with_new_hazards, r.runs)}",
             f"runs that acted on a safe object: {_pct(r.runs_acting_on_safe, r.runs)}"]
    if r.detection:
        d = r.detection
        lines.append(f"detection against the truth: recall {d['recall']:.2f}, precision {d['precision']:.2f}, "
                     f"false alarms on hazard-free scenes {d['false_alarm_rate'] if d['false_alarm_rate'] is not None else '-'}")
    if r.failed:
        lines.append(f"episodes that failed (no verdict): {r.failed}")
    return lines


def print_report(r: BenchReport) -> None:
    from rich.console import Console

    from anomalygen.tables import name_table

    console = Console(stderr=True)
    detected = any(row.detected is not None for row in r.by_class.values())
    cols = ("hazards", *(("detected",) if detected else ()), "resolved (runs)")
    t = name_table("the referee's verdict by hazard class", "hazard class", cols, [*r.by_class, "all"])
    tot = BenchClassRow(detected=0 if detected else None)
    for name, row in r.by_class.items():
        tot.hazards += row.hazards
        tot.runs += row.runs
        tot.resolved += row.resolved
        if detected:
            tot.detected += row.detected or 0
        t.add_row(*_cells(name, row, detected))
    t.add_row(*_cells("all", tot, detected))
    console.print(t)
    for line in headline(r):
        console.print(line)


def _cells(name: str, row: BenchClassRow, detected: bool) -> list[str]:
    out = [name, str(row.hazards)]
    if detected:
        out.append(str(row.detected or 0))
    out.append(f"{row.resolved}/{row.runs}")
    return out


def page(r: BenchReport) -> str:
    """The report as one self-contained HTML page."""
    from anomalygen.evaluate.html_parts import esc, html_table, section

    detected = any(row.detected is not None for row in r.by_class.values())
    head = ["hazard class", "hazards", *(["detected"] if detected else []), "resolved / runs"]
    rows = [[k, v.hazards, *([v.detected] if detected else []), f"{v.resolved} / {v.runs}"] for k, v in r.by_class.items()]
    runs = [[x.task_id, x.seed, x.status or "failed", x.calls, x.invalid_calls, ", ".join(x.new_hazards),
             ", ".join(x.interventions_on_safe), x.error or ""] for x in r.per_run]
    body = "".join([
        section("summary", "Summary", "<ul>" + "".join(f"<li>{esc(line)}</li>" for line in headline(r)) + "</ul>"
                f"<p>suite folder {esc(r.suite_dir)}; code {esc(r.package_version)} at {esc(r.git_commit or '?')}; "
                f"{esc(r.created)}</p>"),
        section("classes", "By hazard class (the referee's verdict)", html_table(head, rows)),
        section("runs", "Every run", html_table(["scene", "seed", "verdict", "calls", "invalid calls", "new hazards",
                                                 "safe objects moved", "error"], runs)),
    ])
    return (f"<!doctype html><html><head><meta charset='utf-8'><title>{esc(r.agent)} on {esc(r.suite)}</title>"
            "<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}"
            "td,th{border:1px solid #ccc;padding:2px 6px}</style></head>"
            f"<body><h1>{esc(r.agent)} on {esc(r.suite)}</h1>{body}</body></html>")
