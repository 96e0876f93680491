"""Issue 15: the report's ablation and detection tables show measured numbers beside the paper's.

A run whose detections came from two detectors must say so (never labelled by one of them), and the
ablation table must carry this run's own diversity per engine and mode, labelled, next to the paper's
figures, with each WMD column's direction stated.
"""

from __future__ import annotations

from anomalygen.config import Settings
from anomalygen.evaluate import run_metrics as rm
from anomalygen.evaluate.baselines import PAPER_ABLATION
from anomalygen.evaluate.detection_report import summarise
from anomalygen.evaluate.report import Report, ablation_rows, render_markdown, run_stage
from anomalygen.evaluate.scored_sections import detection_rows
from anomalygen.evaluate.stage import evaluate_run
from anomalygen.runfolder import read_jsonl, write_jsonl
from anomalygen.schema import Detection, Engine

from .conftest import build_synthetic_run


def _settings():
    s = Settings(quiet=True)
    s.evaluate.baselines = False
    s.evaluate.image_metrics = False
    s.evaluate.wmd_pairs = 10
    return s


def _mixed_run(tmp_path):
    run = build_synthetic_run(tmp_path / "mixed", stages=("brainstorm", "build", "detect"))
    dets = read_jsonl(run.detections_path, Detection)
    for d in dets[:2]:
        d.detector = "llm"
    write_jsonl(run.detections_path, dets)
    tasks = run.load_tasks()
    for t in tasks[:2]:
        t.provenance.engine = Engine.LLM
    write_jsonl(run.tasks_path, tasks)
    return run, dets, tasks


def test_mixed_detectors_are_named_per_scene_and_in_the_label(tmp_path):
    run, dets, tasks = _mixed_run(tmp_path)
    report = summarise(dets, tasks, rm.load_manifests(run, tasks), 3)
    assert report.detector == "mixed (llm 2, rules 3)" and report.detectors == {"llm": 2, "rules": 3}
    ev = evaluate_run(run, _settings())
    assert ev.detection.detector == "mixed (llm 2, rules 3)"
    headers, rows, classes = detection_rows(ev.detection)
    labels = [r[0] for r in rows]
    assert labels == ["measured: llm", "measured: rules", "measured: all (mixed (llm 2, rules 3))", "paper (human-judged)"]
    assert rows[0][1] == 2 and rows[1][1] == 3 and classes[-1] == "paper"
    assert headers[5] == "hit@1 (single-hazard scenes)" and rows[-1][5:] == ["0.76", "0.80", "0.82"]
    # per-detector scores come from that detector's scenes only: the llm's two name their hazard at ranks 1, 2
    assert rows[0][2] == "1.00" and rows[0][5] == "0.50" and rows[1][2] == f"{2 / 3:.2f}"
    # the text judge is there, labelled a diagnostic, never in the score rows
    assert ev.detection.text_judge.label == "text judge vs task description (diagnostic)"
    assert not any("text judge" in str(r[0]) for r in rows)


def test_ablation_table_has_measured_rows_per_engine_beside_the_paper(tmp_path):
    run, _, _ = _mixed_run(tmp_path)
    ev = evaluate_run(run, _settings())
    assert {(a.engine, a.mode, a.tasks) for a in ev.ablation} == {("llm", "brainstorm", 2), ("knowledge", "brainstorm", 3)}
    diversity = {r.name: r for r in ev.diversity}
    measured = next(a for a in ev.ablation if a.engine == "knowledge")
    assert measured.sbert == diversity["mixed [engine=knowledge mode=brainstorm]"].sbert
    headers, rows, classes = ablation_rows(ev)
    assert "WMD ↑ (ours)" in headers and "WMD ↓ (paper, as published)" in headers
    sources = [r[1] for r in rows]
    assert sources.count("paper") == 3
    assert "measured (llm engine)" in sources and "measured (knowledge engine)" in sources
    paper_brainstorm = next(r for r in rows if r[0] == "brainstorm" and r[1] == "paper")
    assert paper_brainstorm[5] == "" and paper_brainstorm[6] == f"{PAPER_ABLATION['brainstorm'][2]:.3f}"
    ours = next(r for r in rows if r[1] == "measured (knowledge engine)")
    assert ours[6] == "" and ours[5] == f"{measured.wmd:.3f}"


def test_report_files_carry_both_tables(tmp_path):
    run, _, _ = _mixed_run(tmp_path)
    run_stage(run, _settings())
    html = (run.report_dir / "index.html").read_text()
    assert "measured (knowledge engine)" in html and "paper (human-judged)" in html and "mixed (llm 2, rules 3)" in html
    md = (run.report_dir / "summary.md").read_text()
    assert "### Brainstorming ablation" in md and "measured: llm" in md
    assert render_markdown(Report.model_validate_json((run.report_dir / "report.json").read_text())).count("paper") >= 4
