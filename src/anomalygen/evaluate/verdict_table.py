"""The referee's verdicts as a terminal table: each class under its own category, names whole.

Headline columns are the referee's (resolved over the runs on scenes that held a hazard; hazard-free
scenes as "no action needed / acted on safe", never as resolved); the robot's own check is the last
column, labelled as such.
"""

from __future__ import annotations

from anomalygen.evaluate.rate import Rate
from anomalygen.evaluate.results import SuccessSummary, VerdictCounts
from anomalygen.tables import group_table

COLUMNS = ("resolved", "no action / on safe", "new hazard", "robot's own check")


def resolved_cell(v: VerdictCounts) -> str:
    return f"{v.resolved}/{v.hazard_runs} ({v.rate:.0%})" if v.hazard_runs else "-"


def hazard_free_cell(v: VerdictCounts) -> str:
    return f"{v.no_action_needed} / {v.acted_on_safe}" if v.hazard_free_runs else "-"


def robot_cell(r: Rate | None) -> str:
    return f"{r.successes}/{r.n}" if r is not None and r.n else "-"


def _cells(v: VerdictCounts, robot: Rate | None) -> list[str]:
    return [resolved_cell(v), hazard_free_cell(v), str(v.new_hazards), robot_cell(robot)]


def verdict_table(s: SuccessSummary):
    rows: dict[str, list[tuple[str, list[str]]]] = {}
    for hazard_class, v in s.by_class.items():
        category = s.class_category.get(hazard_class, "unknown")
        rows.setdefault(category, []).append((hazard_class, _cells(v, s.robot_check_by_class.get(hazard_class))))
    totals = {c: _cells(v, robot_of_category(s, c)) for c, v in s.by_category.items()}
    title = (f"referee's verdict, {s.verdicts.runs} runs judged ({s.unjudged} without truth); "
             "no action / on safe: hazard-free scenes")
    return group_table(title, COLUMNS, dict(sorted(rows.items())), totals,
                       overall=_cells(s.verdicts, s.robot_check))


def robot_of_category(s: SuccessSummary, category: str) -> Rate:
    out = Rate()
    for hazard_class, r in s.robot_check_by_class.items():
        if s.class_category.get(hazard_class) == category:
            out.n += r.n
            out.successes += r.successes
    return out
