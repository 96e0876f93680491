"""The report's scored sections: detection against the truth and the referee's verdicts.

Every headline here covers every class and comes from the answer key's side: detection claims
matched to each scene's truth, runs judged by the referee (``evaluate/verdicts.py``). The robot's
own check appears only beside a headline, labelled "robot's own check"; the text judge only as a
labelled diagnostic; a figure over a subset (single-hazard scenes, scenes with a hazard) says so.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from anomalygen.evaluate import plots
from anomalygen.evaluate.baselines import PAPER_DETECTION
from anomalygen.evaluate.html_parts import esc, fmt, html_table, img
from anomalygen.evaluate.verdict_table import hazard_free_cell, resolved_cell, robot_cell, robot_of_category

if TYPE_CHECKING:
    from anomalygen.evaluate.detection_report import DetectionReport
    from anomalygen.evaluate.results import Evaluation, SuccessSummary

PAPER_SUCCESS = "Paper: 83% (human-judged)."


def detection_rows(d) -> tuple[list[str], list[list], list[str]]:
    """Scores against the truth per detector (and over all scenes when mixed); hit@k on single-hazard
    scenes beside the paper's human-judged hit@k, the only figure of ours comparable with it."""
    ks = list(range(1, d.k + 1))

    def row(label: str, sc) -> list:
        alarms = "—" if sc.false_alarm_rate is None else fmt(sc.false_alarm_rate, 2)
        return [label, sc.scenes, fmt(sc.recall, 2), fmt(sc.precision, 2), alarms,
                *[fmt(sc.hit_at_k.get(k), 2) for k in ks]]

    rows: list[list] = [row(f"measured: {name}", sc) for name, sc in d.per_detector.items()]
    if len(d.per_detector) > 1 and d.overall is not None:
        rows.append(row(f"measured: all ({d.detector})", d.overall))
    rows.append(["paper (human-judged)", "—", "—", "—", "—", *[fmt(PAPER_DETECTION.get(k), 2) for k in ks]])
    headers = ["detector", "scenes", "recall", "precision", "false alarms",
               *[f"hit@{k} (single-hazard scenes)" for k in ks]]
    return headers, rows, [""] * (len(rows) - 1) + ["paper"]


def text_judge_rows(d) -> tuple[list[str], list[list]]:
    """The text judge's hit@k per detector: a diagnostic, labelled as one."""
    tj = d.text_judge
    ks = list(range(1, d.k + 1))
    rows = [[f"{tj.label}: {name}", *[fmt(v.get(k), 2) for k in ks]] for name, v in tj.by_detector.items()]
    if len(tj.by_detector) > 1:
        rows.append([f"{tj.label}: all", *[fmt(tj.hit_at_k.get(k), 2) for k in ks]])
    return ["diagnostic (not a score)", *[f"hit@{k}" for k in ks]], rows


def overview_tiles(ev: Evaluation) -> list[tuple[str, str]]:
    """The headline tiles: detection against the truth and the referee's verdicts, every class; the
    robot's own check only beside them, labelled."""
    kpis = [("tasks", str(ev.tasks)), ("scenes built", str(ev.scenes_built))]
    sc = ev.detection.overall if ev.detection else None
    if sc is not None:
        kpis.append(("detection recall (truth)", f"{sc.found}/{sc.hazards}"))
        kpis.append(("detection precision (truth)", fmt(sc.precision, 2)))
        if sc.false_alarm_rate is not None:
            kpis.append(("false alarms, hazard-free scenes", fmt(sc.false_alarm_rate, 2)))
    if ev.success:
        v = ev.success.verdicts
        kpis.append(("resolved (referee)", f"{v.resolved}/{v.hazard_runs}" if v.hazard_runs else "—"))
        if v.hazard_free_runs:
            kpis.append(("hazard-free: no action needed / acted on safe", f"{v.no_action_needed} / {v.acted_on_safe}"))
        kpis.append(("runs that created a hazard", str(v.new_hazards)))
        r = ev.success.robot_check
        kpis.append(("robot's own check", f"{r.successes}/{r.n}"))
    return kpis


def hazard_table_html(t) -> str:
    """Per class, against the hidden truth: hazards present, detected, planned, resolved; then the harm."""
    def pct(a: int, b: int) -> str:
        return f"{a} ({a / b:.0%})" if b else "-"

    rows = [[name, r.hazards, pct(r.detected, r.hazards), pct(r.planned, r.hazards), f"{pct(r.resolved, r.runs)} of {r.runs}"]
            for name, r in [*t.by_class.items(), ("all classes", t.total)]]
    table = html_table(["hazard class", "hazards present", "detected", "planned", "resolved (runs)"], rows)
    return (f"<p>Every hazard in every scene's hidden truth, by class: {t.scenes} scenes, "
            f"{t.hazard_free_scenes} of them hazard-free. Runs that created a new hazard: "
            f"{pct(t.runs_with_new_hazards, t.runs)}; runs that acted on an already-safe object: "
            f"{pct(t.runs_acting_on_safe, t.runs)}.</p>{table}")


def detection_html(d: DetectionReport) -> str:
    sc = d.overall
    alarms = "no hazard-free scenes" if sc.false_alarm_rate is None else (
        f"{fmt(sc.false_alarm_rate, 2)} over {sc.hazard_free_scenes} hazard-free scenes")
    scores = html_table(
        ["against the hidden truth, every scene", "value"],
        [["hazards found (recall)", f"{sc.found}/{sc.hazards} ({fmt(sc.recall, 2)})"],
         ["claims that were right (precision)", f"{sc.true_claims}/{sc.claims} ({fmt(sc.precision, 2)})"],
         ["F1", fmt(sc.f1, 2)],
         ["false alarms", alarms]])
    headers, rows, classes = detection_rows(d)
    by_cat = html_table(["category / hazard class", "hazards", "found", "recall"], _recall_rows(d))
    diagnostic = ""
    if d.text_judge is not None and d.text_judge.scenes:
        diagnostic = (f"<h3>{esc(d.text_judge.label)}</h3><p>Whether a hypothesis reads like the hidden task's "
                      "description (exact class and object, or calibrated text similarity). A diagnostic, "
                      "not a score: it can credit a detection the truth does not.</p>"
                      + html_table(*text_judge_rows(d)))
    plot = img(plots.hit_at_k_plot(sc.hit_at_k, subset=f"{sc.single_hazard_scenes} single-hazard scenes"),
               "hit at k on single-hazard scenes")
    return (f'<div class="plots">{plot}<div>'
            f"<p>{d.scenes} scenes, detector: {esc(d.detector)}, {d.errors} detector errors; every claim is matched "
            f"to the hazards of the scene's truth.json.</p>{scores}{html_table(headers, rows, classes)}{by_cat}"
            f"</div></div>{diagnostic}")


def _recall_rows(d: DetectionReport) -> list[list]:
    rows: list[list] = []
    totals = d.per_category_found()
    for cat, classes in d.per_category.items():
        t = totals[cat]
        rows.append([cat, t.n, t.successes, fmt(t.rate, 2)])
        rows.extend([f"\u2003{cls}", f.n, f.successes, fmt(f.rate, 2)] for cls, f in classes.items())
    return rows


def success_html(s: SuccessSummary) -> str:
    bars = img(plots.success_bars({k: (v.resolved, v.hazard_runs) for k, v in s.by_category.items()},
                                  title="Resolved by category (referee; runs on scenes with a hazard)",
                                  ylabel="resolved rate"), "resolved by category")
    rows = []
    for cat in sorted({*s.class_category.values()} | set(s.by_category)):
        if cat in s.by_category:
            v = s.by_category[cat]
            rows.append([cat, v.runs, resolved_cell(v), hazard_free_cell(v), v.new_hazards, ""])
        for cls, v in s.by_class.items():
            if s.class_category.get(cls) == cat:
                rows.append([f"\u2003{cls}", v.runs, resolved_cell(v), hazard_free_cell(v), v.new_hazards,
                             robot_cell(s.robot_check_by_class.get(cls))])
    headers = ["category / hazard class", "runs judged", "resolved (referee)",
               "hazard-free: no action needed / acted on safe", "created a hazard", "robot's own check"]
    meth_rows = [[k, v.successes, v.n, fmt(v.rate, 2)] for k, v in s.by_method.items()]
    methods = html_table(["sub-task method (robot's own check)", "held", "runs", "rate"], meth_rows)
    v = s.verdicts
    resolved = f"{v.resolved}/{v.hazard_runs} ({fmt(v.rate, 2)})" if v.hazard_runs else "no run on a scene with a hazard"
    return (f'<div class="plots">{bars}<div>{html_table(headers, rows)}{methods}</div></div>'
            f"<p>Runs resolved, judged by the referee against the builder's hidden truth on every class: "
            f"<b>{resolved}</b> (resolved = every hazard fixed and no new one created). Hazard-free scenes: "
            f"{v.no_action_needed} left alone (no action needed), {v.acted_on_safe} acted on safe. Runs that "
            f"created a new hazard: {v.new_hazards}; runs that acted on an already-safe object: {v.on_safe}; "
            f"{s.unjudged} runs without a truth.json; {s.errors} ended with an error. Robot's own check (its "
            f"plan's final condition held): {s.robot_check.successes}/{s.robot_check.n}. {PAPER_SUCCESS}</p>")


def detection_markdown(d: DetectionReport | None) -> list[str]:
    if d is None or d.overall is None:
        return ["not run" if d is None else "no scene has a truth.json to score against"]
    sc = d.overall
    alarms = "n/a" if sc.false_alarm_rate is None else f"{sc.false_alarm_rate:.2f}"
    lines = [f"Against the truth over {sc.scenes} scenes (detector: {d.detector}): recall {sc.recall:.2f} "
             f"({sc.found}/{sc.hazards}), precision {sc.precision:.2f}, F1 {sc.f1:.2f}, false alarms on "
             f"hazard-free scenes {alarms}.", "", *_md_table(*detection_rows(d)[:2])]
    if d.text_judge is not None and d.text_judge.scenes:
        lines += ["", f"{d.text_judge.label}, not a score:", "", *_md_table(*text_judge_rows(d))]
    return lines


def success_markdown(s: SuccessSummary | None) -> list[str]:
    if s is None:
        return ["not run"]
    lines = ["| category | runs judged | resolved (referee) | hazard-free: no action / on safe | robot's own check |",
             "|---|---:|---:|---:|---:|"]
    robot = {c: robot_of_category(s, c) for c in s.by_category}
    lines += [f"| {k} | {v.runs} | {resolved_cell(v)} | {hazard_free_cell(v)} | {robot_cell(robot[k])} |"
              for k, v in s.by_category.items()]
    v = s.verdicts
    lines.append(f"| **all** | {v.runs} | {resolved_cell(v)} | {hazard_free_cell(v)} | {robot_cell(s.robot_check)} |")
    return lines


def _md_table(headers: list[str], rows: list[list]) -> list[str]:
    return (["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
            + ["| " + " | ".join(str(c) for c in r) + " |" for r in rows])
