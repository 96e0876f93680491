"""CLI tables at 80 columns: hazard class names stay whole, each class under its own category."""

from __future__ import annotations

import pytest
from rich.console import Console

from anomalygen.knowledge import load_kb

WIDTH = 80


def render(renderable) -> str:
    console = Console(width=WIDTH, record=True, color_system=None)
    console.print(renderable)
    return console.export_text()


@pytest.fixture(scope="module")
def classes_by_category() -> dict[str, list[str]]:
    kb = load_kb()
    out: dict[str, list[str]] = {}
    for cid, hc in sorted(kb.hazard_classes.items()):
        out.setdefault(str(hc.category), []).append(cid)
    return out


def assert_grouped(text: str, classes_by_category: dict[str, list[str]]) -> None:
    """Every class appears whole on a line of its own, below its category and above the next one."""
    assert "…" not in text
    lines = text.splitlines()

    def line_of(name: str, indented: bool) -> int:
        hits = [i for i, line in enumerate(lines) if f"{'  ' if indented else ''}{name} " in line.replace("│", " ")]
        assert hits, f"{name} not shown whole"
        return hits[0]

    starts = sorted((line_of(cat, False), cat) for cat in classes_by_category)
    for n, (start, cat) in enumerate(starts):
        end = starts[n + 1][0] if n + 1 < len(starts) else len(lines)
        for cls in classes_by_category[cat]:
            assert start < line_of(cls, True) < end, (cls, cat)


def test_group_table_keeps_every_class_whole_at_80_columns(classes_by_category):
    from anomalygen.tables import group_table

    columns = ("hazards", "found", "recall", "resolved (referee)", "robot's own check")
    rows = {cat: [(cls, ["12", "11", "0.92", "11/12 (92%)", "12/12"]) for cls in members]
            for cat, members in classes_by_category.items()}
    text = render(group_table("a wide table", columns, rows, {c: ["1"] * 5 for c in rows}, overall=["9"] * 5))
    assert max(len(line) for line in text.splitlines()) <= WIDTH
    assert_grouped(text, classes_by_category)


def test_detection_table_lists_each_class_under_its_own_category(classes_by_category):
    from anomalygen.evaluate.detection_report import DetectionReport, print_report
    from anomalygen.evaluate.detection_scores import DetectionScores
    from anomalygen.evaluate.rate import Rate

    scores = DetectionScores(scenes=30, hazards=40, found=38, claims=45, true_claims=38, recall=0.95,
                             precision=0.84, f1=0.89, single_hazard_scenes=20, hit_at_k={1: 0.9, 2: 1.0})
    report = DetectionReport(detector="rules", k=2, scenes=30, overall=scores,
                             per_category={c: {cls: Rate(n=3, successes=2) for cls in members}
                                           for c, members in classes_by_category.items()})
    console = Console(width=WIDTH, record=True, color_system=None)
    print_report(report, console=console)
    assert_grouped(console.export_text(), classes_by_category)


def test_the_referees_table_groups_classes_and_labels_the_robots_check(classes_by_category):
    from anomalygen.evaluate.rate import Rate
    from anomalygen.evaluate.results import SuccessSummary, VerdictCounts
    from anomalygen.evaluate.verdict_table import COLUMNS, verdict_table

    counts = VerdictCounts(runs=4, resolved=2, unresolved=1, no_action_needed=1)
    s = SuccessSummary(results=4, tasks=4, verdicts=counts,
                       by_category={c: counts for c in classes_by_category},
                       by_class={cls: counts for members in classes_by_category.values() for cls in members},
                       class_category={cls: c for c, members in classes_by_category.items() for cls in members},
                       robot_check=Rate(n=4, successes=4))
    text = render(verdict_table(s))
    assert_grouped(text, classes_by_category)
    header = " ".join(text.split("┡")[0].replace("┃", " ").split())  # wrapped header words, in order
    assert COLUMNS[-1] == "robot's own check" and all(w in header for w in COLUMNS[-1].split())
    assert "2/3 (67%)" in text


def test_brainstorm_and_learn_tables_at_80_columns(capsys, monkeypatch, classes_by_category):
    from anomalygen.brainstorm.stage import print_distribution
    from anomalygen.learn.stage import _print_table

    monkeypatch.setenv("COLUMNS", str(WIDTH))
    kb = load_kb()
    tasks = []
    for cid in kb.hazard_classes:
        tasks.append(type("T", (), {"category": kb.hazard_classes[cid].category, "hazard_class": cid})())
    print_distribution(tasks)
    assert_grouped(capsys.readouterr().err, classes_by_category)
    row = {"n": 3, "success": 3, "judged": 3, "resolved": 2, "new_hazards": 1, "on_safe": 0}
    _print_table({cid: row for cid in kb.hazard_classes})
    err = capsys.readouterr().err.replace("│", " ")
    assert "…" not in err and all(f" {cid} " in err for cid in kb.hazard_classes)
