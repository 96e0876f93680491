"""``anomalygen report``: ``report/index.html`` (self-contained), ``report/report.json`` and ``report/summary.md``.

The HTML has inline CSS, plots as base64 PNG, scene renders embedded as base64 and the skill videos
copied next to it (``report/videos/``, relative links), so the folder can be zipped or served as is.
Each section copes with its stage not having run and says so. Metrics come from ``evaluation.json``;
when it is missing the metrics are computed here (without printing) so ``report`` alone works.
"""

from __future__ import annotations

import base64
import html
import shutil
import time
from pathlib import Path
from typing import TYPE_CHECKING

from pydantic import Field

from anomalygen.evaluate import plots
from anomalygen.evaluate import run_metrics as rm
from anomalygen.evaluate.baselines import PAPER_ABLATION, PAPER_DETECTION
from anomalygen.evaluate.results import Evaluation
from anomalygen.runfolder import RunFolder, atomic_write_text, now_iso, write_model
from anomalygen.runner import StageSummary
from anomalygen.schema import Artefact, StageRecord, Strict

if TYPE_CHECKING:
    from anomalygen.config import Settings

SECTIONS = ("overview", "diversity", "categories", "detection", "success", "gallery", "timings", "llm")
NOT_RUN = "not run"


class GalleryItem(Strict):
    task_id: str
    name: str
    category: str
    hazard_class: str
    description: str
    render: str | None = Field(None, description="render file, relative to the run folder")
    videos: list[str] = Field(default_factory=list, description="copied videos, relative to report/")
    hit_rank: int | None = None
    detected: bool | None = None
    success: bool | None = Field(None, description="the referee's verdict: resolved in most judged runs (None: not judged)")


class Report(Artefact):
    generated: str
    evaluation: Evaluation
    gallery: list[GalleryItem] = Field(default_factory=list)


# --------------------------------------------------------------------------- collecting


def collect_gallery(run: RunFolder) -> list[GalleryItem]:
    """One entry per task (or per built scene when there is no tasks.jsonl), renders and videos attached."""
    tasks = rm.load_tasks(run)
    detections = {d.task_id: d for d in rm.load_detections(run)}
    results: dict[str, list] = {}
    for r in rm.load_skill_results(run):
        results.setdefault(r.task_id, []).append(r)
    verdicts: dict[str, list] = {}
    for (tid, _), v in rm.load_verdicts(run).items():
        verdicts.setdefault(tid, []).append(v.resolved)
    ids = [t.id for t in tasks] or sorted(p.parent.name for p in rm.scene_renders(run))
    by_id = {t.id: t for t in tasks}
    items = []
    for tid in ids:
        t = by_id.get(tid)
        render = run.scene_dir(tid) / "render_front.png"
        videos = []
        for res in sorted(results.get(tid, []), key=lambda r: r.seed):
            if _find_video(run, tid, res.seed, res.video) is not None:
                videos.append(f"videos/{tid}_seed{res.seed}.mp4")
        det = detections.get(tid)
        judged = verdicts.get(tid, [])
        items.append(GalleryItem(
            task_id=tid,
            name=t.name if t else tid,
            category=str(t.category) if t else "unknown",
            hazard_class=t.hazard_class if t else "unknown",
            description=t.description if t else "",
            render=str(render.relative_to(run.root)) if render.is_file() else None,
            videos=videos,
            hit_rank=det.hit_rank if det else None,
            detected=(det.hit_rank is not None) if det else None,
            success=(sum(judged) * 2 > len(judged)) if judged else None,
        ))
    return items


def _find_video(run: RunFolder, task_id: str, seed: int, declared: str | None = None) -> Path | None:
    """The skill's video: the declared path (relative to the seed folder or the run), else any mp4 there."""
    folder = run.skill_dir(task_id, seed)
    candidates = [folder / declared, run.root / declared] if declared else []
    candidates += [folder / "video.mp4", *sorted(folder.glob("*.mp4"))]
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


def _e(x) -> str:
    return html.escape(str(x))


def _f(x: float | None, digits: int = 3) -> str:
    return "—" if x is None else f"{x:.{digits}f}"


def _table(headers: list[str], rows: list[list], row_classes: list[str] | None = None) -> str:
    head = "".join(f"<th>{_e(h)}</th>" for h in headers)
    body = []
    for i, row in enumerate(rows):
        cls = f' class="{row_classes[i]}"' if row_classes and row_classes[i] else ""
        body.append(f"<tr{cls}>" + "".join(f"<td>{_e(c)}</td>" for c in row) + "</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def _img(b64: str | None, alt: str) -> str:
    return f'<img alt="{_e(alt)}" src="data:image/png;base64,{b64}">' if b64 else ""


def _section(sid: str, title: str, body: str) -> str:
    return f'<section id="{sid}"><h2>{_e(title)}</h2>{body}</section>'


def _not_run(stage: str) -> str:
    return f'<p class="notrun">{NOT_RUN}: the {_e(stage)} stage has produced no artefacts yet.</p>'


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


def detection_rows(d) -> tuple[list[str], list[list], list[str]]:
    """hit@k measured per detector (and over all scenes when mixed) beside the paper's human-judged rates."""
    ks = sorted(d.hit_at_k)
    rows: list[list] = [[f"measured: {name}", d.detectors.get(name, 0), *[_f(v.get(k), 2) for k in ks]] for name, v in d.by_detector.items()]
    if len(d.by_detector) > 1:
        rows.append([f"measured: all ({d.detector_label})", d.scenes, *[_f(d.hit_at_k.get(k), 2) for k in ks]])
    rows.append(["paper (human-judged)", "—", *[_f(PAPER_DETECTION.get(k), 2) for k in ks]])
    return ["detector", "scenes", *[f"hit@{k}" for k in ks]], rows, [""] * (len(rows) - 1) + ["paper"]


def _hazard_table_html(t) -> str:
    """Per class, against the hidden truth: hazards present, detected, planned, resolved; then the harm."""
    def pct(a: int, b: int) -> str:
        return f"{a} ({a / b:.0%})" if b else "-"

    rows = [[name, r.hazards, pct(r.detected, r.hazards), pct(r.planned, r.hazards), f"{pct(r.resolved, r.runs)} of {r.runs}"]
            for name, r in [*t.by_class.items(), ("all classes", t.total)]]
    table = _table(["hazard class", "hazards present", "detected", "planned", "resolved (runs)"], rows)
    return (f"<p>Every hazard in every scene's hidden truth, by class: {t.scenes} scenes, "
            f"{t.hazard_free_scenes} of them hazard-free. Runs that created a new hazard: "
            f"{pct(t.runs_with_new_hazards, t.runs)}; runs that acted on an already-safe object: "
            f"{pct(t.runs_acting_on_safe, t.runs)}.</p>{table}")


def render_html(report: Report, run: RunFolder) -> str:
    ev = report.evaluation
    parts = []

    # overview
    kpis = [("tasks", ev.tasks), ("scenes built", ev.scenes_built)]
    if ev.detection:
        kpis.append(("hit@1", _f(ev.detection.hit_at_k.get(1), 2)))
        kpis.append((f"hit@{ev.detection.k}", _f(ev.detection.hit_at_k.get(ev.detection.k), 2)))
    if ev.success:
        kpis.append(("success", f"{ev.success.overall.successes}/{ev.success.overall.n}"))
    kpi_html = '<div class="kpi">' + "".join(f"<div><b>{_e(v)}</b>{_e(k)}</div>" for k, v in kpis) + "</div>"
    missing = f'<p class="notrun">{NOT_RUN}: {_e(", ".join(ev.not_run))}</p>' if ev.not_run else ""
    parts.append(_section("overview", "Overview", kpi_html + missing))

    # diversity
    if ev.diversity:
        rows = [[r.name, r.kind, r.tasks, _f(r.self_bleu), _f(r.sbert), _f(r.wmd), _f(r.image), _f(r.clip)] for r in ev.diversity]
        table = _table(["set", "source", "tasks", "Self-BLEU ↓", "SBERT sim ↓", "WMD ↑", "image sim ↓", "CLIP sim ↓"],
                       rows, [r.kind if r.kind != "baseline" else "" for r in ev.diversity])
        embedders = sorted({r.image_embedder for r in ev.diversity if r.kind == "run" and r.image_embedder})
        note = ("<p>Text = task name + description. Baselines are recomputed from the packaged public task lists; "
                "“paper” rows are the published figures (ViT/CLIP image columns). Our image column uses "
                f"{_e(', '.join(embedders) or 'no image embedder')}; WMD uses MiniLM word-piece vectors.</p>")
        headers, rows, classes = ablation_rows(ev)
        ablation = _table(headers, rows, classes) + ("<p>Measured rows are this run's proposals grouped by engine and "
                                                      "mode; the paper's are published. The paper reads its WMD as lower "
                                                      "is better; ours is a distance, so higher means more diverse.</p>")
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
    if ev.detection:
        d = ev.detection
        ks = sorted(d.hit_at_k)
        by_cat = _table(["category", *[f"hit@{k}" for k in ks]],
                        [[c, *[_f(v.get(k), 2) for k in ks]] for c, v in d.by_category.items()])
        scored = ""
        if d.scores is not None:
            sc = d.scores
            alarms = "no hazard-free scenes" if sc.false_alarm_rate is None else (
                f"{_f(sc.false_alarm_rate, 2)} over {sc.hazard_free_scenes} hazard-free scenes")
            scored = _table(
                ["against the hidden truth", "value"],
                [["hazards found (recall)", f"{sc.found}/{sc.hazards} ({_f(sc.recall, 2)})"],
                 ["claims that were right (precision)", f"{sc.true_claims}/{sc.claims} ({_f(sc.precision, 2)})"],
                 ["F1", _f(sc.f1, 2)],
                 ["false alarms", alarms],
                 *[[f"hit@{j} on {sc.single_hazard_scenes} single-hazard scenes", _f(v, 2)]
                   for j, v in sorted(sc.hit_at_k.items())]])
        headers, rows, classes = detection_rows(d)
        by_detector = _table(headers, rows, classes)
        body = (f'<div class="plots">{_img(plots.hit_at_k_plot(d.hit_at_k), "hit at k")}<div>'
                f"<p>{d.scenes} scenes, detector: {_e(d.detector_label)}, {d.errors} detector errors.</p>"
                f"{scored}{by_detector}{by_cat}</div></div>")
        parts.append(_section("detection", "Detection hit@k", body))
    else:
        parts.append(_section("detection", "Detection hit@k", _not_run("detect")))

    # success
    if ev.success:
        s = ev.success
        bars = _img(plots.success_bars({k: (v.successes, v.n) for k, v in s.by_category.items()}), "success by category")
        def truth(k: str) -> str:
            r = s.resolved_by_class.get(k)
            return f"{r.successes}/{r.n} ({_f(r.rate, 2)})" if r and r.n else "no truth"

        cls_rows = [[k, v.n, f"{v.successes} ({_f(v.rate, 2)})", truth(k)] for k, v in s.by_class.items()]
        meth_rows = [[k, v.successes, v.n, _f(v.rate, 2)] for k, v in s.by_method.items()]
        headers = ["hazard class", "runs", "robot: plan done", "truth: hazard resolved"]
        resolved = (f"{s.resolved.successes}/{s.resolved.n} ({_f(s.resolved.rate, 2)})" if s.resolved.n
                    else "not judged (no truth.json)")
        body = (f'<div class="plots">{bars}<div>{_table(headers, cls_rows)}'
                f'{_table(["sub-task method", "successes", "runs", "rate"], meth_rows)}</div></div>'
                f"<p>Hazards resolved, judged against the builder's hidden truth on every class: <b>{resolved}</b>. "
                f"The robot's own verdict (its plan's final condition held): {s.overall.successes}/{s.overall.n} "
                f"({_f(s.overall.rate, 2)}) over {s.tasks} tasks. Runs that created a new hazard: {s.new_hazards}; "
                f"runs that acted on an already-safe object: {s.on_safe}; {s.errors} runs ended with an error. "
                "Paper: 83% (human-judged).</p>")
        if ev.hazards is not None:
            body = _hazard_table_html(ev.hazards) + body
        parts.append(_section("success", "Resolution success", body))
    else:
        parts.append(_section("success", "Resolution success", _not_run("learn")))

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
            if g.detected is not None:
                tags += f'<span class="tag {"ok" if g.detected else "bad"}">detected: {_e(g.hit_rank or "miss")}</span>'
            if g.success is not None:
                tags += f'<span class="tag {"ok" if g.success else "bad"}">{"resolved" if g.success else "unresolved"}</span>'
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
        lines += ["| set | source | tasks | Self-BLEU | SBERT sim | WMD | image sim | CLIP sim |", "|---|---|---:|---:|---:|---:|---:|---:|"]
        lines += [f"| {r.name} | {r.kind} | {r.tasks} | {_f(r.self_bleu)} | {_f(r.sbert)} | {_f(r.wmd)} | {_f(r.image)} | {_f(r.clip)} |"
                  for r in ev.diversity]
    else:
        lines.append(NOT_RUN)
    if ev.diversity:
        lines += ["", "### Brainstorming ablation", "", *_md_table(*ablation_rows(ev)[:2])]
    lines += ["", "## Detection", ""]
    if ev.detection:
        lines.append(", ".join(f"hit@{k} = {v:.2f}" for k, v in sorted(ev.detection.hit_at_k.items()))
                     + f" over {ev.detection.scenes} scenes (detector: {ev.detection.detector_label})")
        lines += ["", *_md_table(*detection_rows(ev.detection)[:2])]
    else:
        lines.append(NOT_RUN)
    lines += ["", "## Success by category", ""]
    if ev.success:
        lines += ["| category | successes | runs | rate |", "|---|---:|---:|---:|"]
        lines += [f"| {k} | {v.successes} | {v.n} | {v.rate:.2f} |" for k, v in ev.success.by_category.items()]
        lines.append(f"| **all** | {ev.success.overall.successes} | {ev.success.overall.n} | {ev.success.overall.rate:.2f} |")
    else:
        lines.append(NOT_RUN)
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
