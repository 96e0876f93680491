"""``anomalygen report``: ``report/index.html`` (self-contained), ``report/report.json`` and ``report/summary.md``.

The HTML has inline CSS, plots as base64 PNG, scene renders embedded as base64 and the skill videos
copied next to it (``report/videos/``, relative links), so the folder can be zipped or served as is.
Each section copes with its stage not having run and says so. Metrics come from ``evaluation.json``;
when it is missing the metrics are computed here (without printing) so ``report`` alone works.
"""

from __future__ import annotations

import base64
import shutil
import time
from pathlib import Path
from typing import TYPE_CHECKING

from pydantic import Field

from anomalygen.evaluate import plots
from anomalygen.evaluate import run_metrics as rm
from anomalygen.evaluate.baselines import PAPER_ABLATION
from anomalygen.evaluate.diversity import DIVERSITY_HEADERS, diversity_cells, table_note
from anomalygen.evaluate.html_parts import NOT_RUN
from anomalygen.evaluate.html_parts import esc as _e
from anomalygen.evaluate.html_parts import fmt as _f
from anomalygen.evaluate.html_parts import html_table as _table
from anomalygen.evaluate.html_parts import img as _img
from anomalygen.evaluate.html_parts import not_run as _not_run
from anomalygen.evaluate.html_parts import section as _section
from anomalygen.evaluate.results import Evaluation
from anomalygen.evaluate.scored_sections import (
    detection_html,
    detection_markdown,
    hazard_table_html,
    overview_tiles,
    success_html,
    success_markdown,
)
from anomalygen.evaluate.verdicts import STATUS_LABELS
from anomalygen.runfolder import RunFolder, atomic_write_text, now_iso, write_model
from anomalygen.runner import StageSummary
from anomalygen.scene_files import VIDEO, render_file
from anomalygen.schema import Artefact, StageRecord, Strict

if TYPE_CHECKING:
    from anomalygen.config import Settings

SECTIONS = ("overview", "diversity", "categories", "detection", "success", "gallery", "timings", "llm")


class GalleryItem(Strict):
    task_id: str
    name: str
    category: str
    hazard_class: str
    description: str
    render: str | None = Field(None, description="render file, relative to the run folder")
    videos: list[str] = Field(default_factory=list, description="copied videos, relative to report/")
    hazards: int | None = Field(None, description="hazards in the scene's truth; None without truth.json")
    found: int | None = Field(None, description="of those, named by the detection; None without a detection")
    verdicts: dict[str, int] = Field(default_factory=dict, description="referee's status -> runs")
    robot_check: int | None = Field(None, description="runs whose plan's own final condition held")
    runs: int = 0


class Report(Artefact):
    generated: str
    evaluation: Evaluation
    gallery: list[GalleryItem] = Field(default_factory=list)


# --------------------------------------------------------------------------- collecting


def collect_gallery(run: RunFolder) -> list[GalleryItem]:
    """One entry per task (or per built scene when there is no tasks.jsonl), renders and videos attached,
    each with what the detection found of its truth and the referee's verdict per run."""
    from anomalygen.evaluate.detection_scores import finds

    tasks = rm.load_tasks(run)
    detections = {d.task_id: d for d in rm.load_detections(run)}
    manifests = rm.load_manifests(run, tasks)
    results: dict[str, list] = {}
    all_results = rm.load_skill_results(run)
    verdicts = rm.load_verdicts(run, all_results)
    for r in all_results:
        results.setdefault(r.task_id, []).append(r)
    ids = [t.id for t in tasks] or sorted(p.parent.name for p in rm.scene_renders(run))
    by_id = {t.id: t for t in tasks}
    items = []
    for tid in ids:
        t = by_id.get(tid)
        render = run.scene_dir(tid) / render_file("front")
        videos = []
        for res in sorted(results.get(tid, []), key=lambda r: r.seed):
            if _find_video(run, tid, res.seed, res.video) is not None:
                videos.append(f"videos/{tid}_seed{res.seed}.mp4")
        det, truth = detections.get(tid), manifests.get(tid)
        seeds = results.get(tid, [])
        statuses: dict[str, int] = {}
        for r in seeds:
            if (v := verdicts.get((tid, r.seed))) is not None:
                statuses[v.status] = statuses.get(v.status, 0) + 1
        items.append(GalleryItem(
            task_id=tid,
            name=t.name if t else tid,
            category=str(t.category) if t else "unknown",
            hazard_class=t.hazard_class if t else "unknown",
            description=t.description if t else "",
            render=str(render.relative_to(run.root)) if render.is_file() else None,
            videos=videos,
            hazards=len(truth.hazards) if truth else None,
            found=sum(finds(det.hypotheses, z) for z in truth.hazards) if truth and det else None,
            verdicts=statuses,
            robot_check=sum(r.success for r in seeds) if seeds else None,
            runs=len(seeds),
        ))
    return items


def _find_video(run: RunFolder, task_id: str, seed: int, declared: str | None = None) -> Path | None:
    """The skill's video: the declared path (relative to the seed folder or the run), else any mp4 there."""
    folder = run.skill_dir(task_id, seed)
    candidates = [folder / declared, run.root / declared] if declared else []
    candidates += [folder / VIDEO, *sorted(folder.glob("*.mp4"))]
    return next((p for p in candidates if p.is_file()), None)


def _copy_videos(run: RunFolder, gallery: list[GalleryItem]) -> None:
    target = run.report_dir / "videos"
    for item in gallery:
        for rel in item.videos:
            seed = int(rel.rsplit("_seed", 1)[1].removesuffix(".mp4"))
            src = _find_video(run, item.task_id, seed)
            if src is None:
                continue
            dst = run.report_dir / rel
            target.mkdir(parents=True, exist_ok=True)
            if not dst.is_file() or dst.stat().st_size != src.stat().st_size:
                tmp = dst.with_suffix(".mp4.tmp")
                shutil.copyfile(src, tmp)
                tmp.replace(dst)


# --------------------------------------------------------------------------- HTML

CSS = """
body{font-family:-apple-system,Segoe UI,Helvetica,Arial,sans-serif;margin:0;background:#f6f7f9;color:#222}
header{background:#1f3b57;color:#fff;padding:18px 32px}header h1{margin:0;font-size:24px}
header p{margin:4px 0 0;opacity:.85}main{padding:8px 32px 40px;max-width:1200px}
section{background:#fff;border-radius:8px;box-shadow:0 1px 3px rgba(0,0,0,.1);padding:14px 20px;margin:16px 0}
h2{margin:4px 0 10px;font-size:19px;color:#1f3b57}table{border-collapse:collapse;font-size:14px;margin:6px 0}
th,td{border-bottom:1px solid #e3e6ea;padding:4px 10px;text-align:right}th{background:#eef1f5}
td:first-child,th:first-child{text-align:left}tr.run td{font-weight:bold;background:#fff8e1}
tr.paper td{color:#666;font-style:italic}.notrun{color:#999;font-style:italic}
.plots{display:flex;flex-wrap:wrap;gap:16px;align-items:flex-start}.plots img{max-width:100%}
.gallery{display:grid;grid-template-columns:repeat(auto-fill,minmax(260px,1fr));gap:14px}
.card{border:1px solid #e3e6ea;border-radius:6px;padding:8px;font-size:13px;background:#fcfcfd}
.card img,.card video{width:100%;border-radius:4px;background:#ddd}.card h3{font-size:14px;margin:6px 0 2px}
.tag{display:inline-block;border-radius:3px;padding:0 6px;margin-right:4px;font-size:12px;background:#e8eef5}
.ok{background:#d9f2df}.bad{background:#f8dcdc}.kpi{display:flex;gap:14px;flex-wrap:wrap}
.kpi div{background:#eef1f5;border-radius:6px;padding:8px 14px}.kpi b{display:block;font-size:20px}
"""


ABLATION_HEADERS = ["mode", "source", "tasks", "Self-BLEU ↓", "SBERT sim ↓", "WMD ↑ (ours)", "WMD ↓ (paper, as published)"]


def ablation_rows(ev: Evaluation) -> tuple[list[str], list[list], list[str]]:
    """Our measured diversity per engine and mode beside the paper's figures, each row labelled."""
    rows: list[list] = []
    classes: list[str] = []
    for mode in ("plain", "roleplay", "brainstorm"):
        for r in (a for a in ev.ablation if a.mode == mode):
            rows.append([mode, f"measured ({r.engine} engine)", r.tasks, _f(r.self_bleu), _f(r.sbert), _f(r.wmd), ""])
            classes.append("")
        bleu, sbert, wmd = PAPER_ABLATION[mode]
        rows.append([mode, "paper", 100, _f(bleu), _f(sbert), "", _f(wmd)])
        classes.append("paper")
    return ABLATION_HEADERS, rows, classes


def render_html(report: Report, run: RunFolder) -> str:
    ev = report.evaluation
    parts = []

    # overview
    kpis = overview_tiles(ev)
    kpi_html = '<div class="kpi">' + "".join(f"<div><b>{_e(v)}</b>{_e(k)}</div>" for k, v in kpis) + "</div>"
    missing = f'<p class="notrun">{NOT_RUN}: {_e(", ".join(ev.not_run))}</p>' if ev.not_run else ""
    parts.append(_section("overview", "Overview", kpi_html + missing))

    # diversity
    if ev.diversity:
        table = _table(DIVERSITY_HEADERS, diversity_cells(ev.diversity),
                       [r.kind if r.kind != "baseline" else "" for r in ev.diversity])
        note = f"<p>{_e(table_note(ev.diversity))}</p>"
        headers, rows, classes = ablation_rows(ev)
        ablation = _table(headers, rows, classes) + ("<p>Measured rows are this run's proposals grouped by engine and "
                                                      "mode (Self-BLEU and SBERT: mean over the draws, as above; WMD: "
                                                      "the whole group); the paper's are published. The paper reads its "
                                                      "WMD as lower is better; ours is a distance, so higher means more "
                                                      "diverse.</p>")
        parts.append(_section("diversity", "Diversity", table + note + "<h3>Brainstorming ablation</h3>" + ablation))
    else:
        parts.append(_section("diversity", "Diversity", _not_run("evaluate")))

    # categories
    if ev.tasks:
        pie = _img(plots.category_pie(ev.categories), "category pie")
        cls_table = _table(["hazard class", "tasks"], [[k, v] for k, v in ev.classes.items()])
        asset_table = _table(["target asset", "tasks"], [[k, v] for k, v in list(ev.target_assets.items())[:20]])
        parts.append(_section("categories", "Categories and classes",
                              f'<div class="plots">{pie}<div>{cls_table}</div><div>{asset_table}</div></div>'))
    else:
        parts.append(_section("categories", "Categories and classes", _not_run("brainstorm")))

    # detection
    if ev.detection and ev.detection.overall is not None:
        parts.append(_section("detection", "Detection against the truth", detection_html(ev.detection)))
    elif ev.detection:
        parts.append(_section("detection", "Detection against the truth",
                              f"<p>{ev.detection.scenes} scenes detected, but no scene has a truth.json to score "
                              "against.</p>"))
    else:
        parts.append(_section("detection", "Detection against the truth", _not_run("detect")))

    # success
    if ev.success:
        body = success_html(ev.success)
        if ev.hazards is not None:
            body = hazard_table_html(ev.hazards) + body
        parts.append(_section("success", "Resolution (referee's verdict)", body))
    else:
        parts.append(_section("success", "Resolution (referee's verdict)", _not_run("learn")))

    # gallery
    if report.gallery:
        cards = []
        for g in report.gallery:
            media = ""
            if g.render:
                data = base64.b64encode((run.root / g.render).read_bytes()).decode("ascii")
                media += f'<img alt="render of {_e(g.task_id)}" src="data:image/png;base64,{data}">'
            else:
                media += f'<p class="notrun">no render ({NOT_RUN})</p>'
            for v in g.videos:
                media += f'<video controls muted preload="metadata" src="{_e(v)}"></video>'
            tags = f'<span class="tag">{_e(g.category)}</span><span class="tag">{_e(g.hazard_class)}</span>'
            if g.hazards is not None and g.found is not None:
                ok = g.found == g.hazards
                tags += f'<span class="tag {"ok" if ok else "bad"}">found {g.found}/{g.hazards} hazards</span>'
            for status, n in sorted(g.verdicts.items()):
                good = status in ("resolved", "no_action_needed")
                tags += f'<span class="tag {"ok" if good else "bad"}">{_e(STATUS_LABELS[status])} ×{n}</span>'
            if g.robot_check is not None:
                tags += f'<span class="tag">robot\'s own check {g.robot_check}/{g.runs}</span>'
            cards.append(f'<div class="card">{media}<h3>{_e(g.name)}</h3>{tags}<p>{_e(g.description)}</p></div>')
        parts.append(_section("gallery", "Scene gallery", f'<div class="gallery">{"".join(cards)}</div>'))
    else:
        parts.append(_section("gallery", "Scene gallery", _not_run("build")))

    # timings
    if ev.timings:
        rows = [[k, v.started or "", v.finished or "", _f(v.wall_s, 1), v.done, v.skipped, v.failed] for k, v in ev.timings.items()]
        parts.append(_section("timings", "Timings", _table(["stage", "started", "finished", "wall s", "done", "skipped", "failed"], rows)))
    else:
        parts.append(_section("timings", "Timings", f'<p class="notrun">{NOT_RUN}: no stage has recorded timings.</p>'))

    # LLM usage
    u = ev.llm_usage
    rows = [["requests", u.requests], ["prompt tokens", u.prompt_tokens], ["completion tokens", u.completion_tokens],
            ["cache hits", u.cache_hits], ["cache misses", u.cache_misses], ["retries", u.retries],
            ["cost (USD)", "—" if u.cost_usd is None else f"{u.cost_usd:.4f}"]]
    note = "" if u.requests else "<p>No LLM requests (offline engines).</p>"
    parts.append(_section("llm", "LLM usage", _table(["", "value"], rows) + note))

    return (
        "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\">"
        f"<title>anomalygen report — {_e(ev.run)}</title><style>{CSS}</style></head><body>"
        f"<header><h1>anomalygen report — {_e(ev.run)}</h1><p>generated {_e(report.generated)}</p></header>"
        f"<main>{''.join(parts)}</main></body></html>\n"
    )


# --------------------------------------------------------------------------- Markdown


def _md_table(headers: list[str], rows: list[list]) -> list[str]:
    return ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)] + ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]


def render_markdown(report: Report) -> str:
    ev = report.evaluation
    lines = [f"# anomalygen report — {ev.run}", "", f"Generated {report.generated}.", ""]
    lines += [f"- tasks: {ev.tasks}", f"- scenes built: {ev.scenes_built} (failed: {ev.scenes_failed})"]
    if ev.not_run:
        lines.append(f"- {NOT_RUN}: {', '.join(ev.not_run)}")
    lines += ["", "## Diversity", ""]
    if ev.diversity:
        lines += [*_md_table(DIVERSITY_HEADERS, diversity_cells(ev.diversity)), "", table_note(ev.diversity)]
    else:
        lines.append(NOT_RUN)
    if ev.diversity:
        lines += ["", "### Brainstorming ablation", "", *_md_table(*ablation_rows(ev)[:2])]
    lines += ["", "## Detection against the truth", "", *detection_markdown(ev.detection)]
    lines += ["", "## Resolved by category (referee's verdict)", "", *success_markdown(ev.success)]
    lines += ["", "## Timings", ""]
    lines += [f"- {k}: {v.wall_s:.1f} s ({v.done} done, {v.skipped} skipped, {v.failed} failed)" for k, v in ev.timings.items()] or [NOT_RUN]
    u = ev.llm_usage
    lines += ["", "## LLM usage", "", f"{u.requests} requests, {u.prompt_tokens} prompt + {u.completion_tokens} completion tokens, "
              f"{u.cache_hits} cache hits" + ("" if u.cost_usd is None else f", ${u.cost_usd:.4f}"), ""]
    return "\n".join(lines)


# --------------------------------------------------------------------------- stage


def build_report(run: RunFolder, settings: Settings) -> Report:
    from anomalygen.evaluate.stage import evaluate_run, load_evaluation

    evaluation = load_evaluation(run) or evaluate_run(run, settings)
    return Report(generated=now_iso(), evaluation=evaluation, gallery=collect_gallery(run))


def run_stage(run: RunFolder, settings: Settings) -> StageSummary:
    started, record = time.perf_counter(), StageRecord(started=now_iso())
    report = build_report(run, settings)
    run.report_dir.mkdir(parents=True, exist_ok=True)
    _copy_videos(run, report.gallery)
    index = run.report_dir / "index.html"
    atomic_write_text(index, render_html(report, run))
    write_model(run.report_dir / "report.json", report)
    atomic_write_text(run.report_dir / "summary.md", render_markdown(report))
    summary = StageSummary("report", done=1, wall_s=time.perf_counter() - started)
    summary.results["index"] = str(index)
    record.finished, record.wall_s, record.done = now_iso(), round(summary.wall_s, 3), 1
    run.record_stage("report", record)
    return summary


def report_path(run: RunFolder) -> Path:
    return run.report_dir / "index.html"
