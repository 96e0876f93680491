"""Run folders written before the detection report and the success summary shared one count model
(``evaluate/rate.py``) still load: their per-category detection counts read ``hazards``/``found``."""

from __future__ import annotations

import json

from anomalygen.evaluate import run_metrics as rm
from anomalygen.evaluate.detection_report import DetectionReport, summarise, summary_path
from anomalygen.evaluate.rate import Rate
from anomalygen.evaluate.results import Evaluation
from anomalygen.evaluate.stage import evaluation_path, load_evaluation
from anomalygen.runfolder import read_model


def _old_shape(report: dict) -> dict:
    """The detection report as written before: per-category cells as {"hazards": n, "found": successes}."""
    old = dict(report)
    old["per_category"] = {cat: {cls: {"hazards": c["n"], "found": c["successes"]} for cls, c in classes.items()}
                           for cat, classes in report["per_category"].items()}
    return old


def test_old_detections_summary_and_evaluation_load(synthetic_run):
    tasks = rm.load_tasks(synthetic_run)
    results = rm.load_skill_results(synthetic_run)
    report = summarise(rm.load_detections(synthetic_run), tasks, rm.load_manifests(synthetic_run, tasks), 3,
                       category_of={t.hazard_class: str(t.category) for t in tasks})
    success = rm.success_summary(results, tasks, rm.load_verdicts(synthetic_run, results))
    now = Evaluation(run="synth", tasks=len(tasks), detection=report, success=success)
    old_report = _old_shape(json.loads(report.model_dump_json()))
    old_eval = json.loads(now.model_dump_json())
    old_eval["detection"] = old_report
    assert old_report["per_category"]["hygiene"] == {"close_open_refrigerator": {"hazards": 1, "found": 1}}
    summary_path(synthetic_run).write_text(json.dumps(old_report, indent=2))
    evaluation_path(synthetic_run).write_text(json.dumps(old_eval, indent=2))

    assert read_model(summary_path(synthetic_run), DetectionReport) == report
    loaded = load_evaluation(synthetic_run)
    assert loaded == now and loaded.detection.per_category["child_safety"]["keep_chemicals_from_children"] == Rate(n=1)
    assert loaded.success.robot_check == Rate(n=5, successes=3)
    # written again, the counts carry the shared names
    cell = json.loads(loaded.model_dump_json())["detection"]["per_category"]["hygiene"]["close_open_refrigerator"]
    assert cell == {"n": 1, "successes": 1}


def test_rate_reads_either_name_and_writes_n_and_successes():
    assert Rate.model_validate({"hazards": 4, "found": 3}) == Rate(n=4, successes=3)
    assert Rate.model_validate_json('{"n": 4, "successes": 3}').rate == 0.75
    assert Rate(n=4, successes=3).model_dump() == {"n": 4, "successes": 3}


# The diversity table as evaluate wrote it before issue 39: whole-set figures, the paper's in rows of their own.
OLD_DIVERSITY = [
    {"name": "synth", "kind": "run", "tasks": 5, "self_bleu": 0.481, "sbert": 0.283, "wmd": 0.55, "image": 0.716,
     "clip": None, "image_embedder": "efficientnet-lite0"},
    {"name": "RoboGen", "kind": "baseline", "tasks": 46, "self_bleu": 0.41, "sbert": 0.44, "wmd": 0.5, "image": None,
     "clip": None, "image_embedder": None},
    {"name": "RoboGen (paper)", "kind": "paper", "tasks": 106, "self_bleu": 0.287, "sbert": 0.394, "wmd": None,
     "image": 0.353, "clip": 0.824, "image_embedder": "ViT / CLIP"},
]


def test_old_diversity_table_loads_and_renders(synthetic_run):
    from anomalygen.evaluate.baselines import PAPER_DIVERSITY
    from anomalygen.evaluate.diversity import PUBLISHED_HEADER, diversity_cells
    from anomalygen.evaluate.report import Report, render_html, render_markdown

    old_eval = json.loads(Evaluation(run="synth", tasks=5).model_dump_json())
    old_eval["diversity"] = OLD_DIVERSITY
    evaluation_path(synthetic_run).write_text(json.dumps(old_eval, indent=2))

    loaded = load_evaluation(synthetic_run)
    run, baseline, paper = loaded.diversity
    assert (run.self_bleu, run.wmd, run.image, run.draw_size, run.draws, run.published) == (0.481, 0.55, 0.716, None, None, None)
    assert paper.published == PAPER_DIVERSITY["RoboGen"] and paper.self_bleu is None and paper.image_embedder is None
    cells = diversity_cells(loaded.diversity)
    assert cells[0][3] == "all 5 (older file: whole set)" and cells[0][4] == "0.481" and cells[0][6] == "0.716"
    assert cells[2][-1].startswith("Self-BLEU 0.287 · SBERT 0.394 · ViT 0.353 · CLIP 0.824")
    report = Report(generated="then", evaluation=loaded)
    assert PUBLISHED_HEADER in render_html(report, synthetic_run) and PUBLISHED_HEADER in render_markdown(report)
    # written again and read back, the row is the same
    assert Evaluation.model_validate_json(loaded.model_dump_json()) == loaded
