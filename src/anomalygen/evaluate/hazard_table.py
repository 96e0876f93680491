"""The loop in one table: per hazard class, hazards present, detected, planned and resolved.

Every figure is counted against the builder's hidden truth (``truth.json``), hazard by hazard, over
every class: a hazard is *detected* when a claim of the scene's detection names it, *planned* when the
scene's plan acts on its object, *resolved* when the referee's verdict found it fixed at the end of a
run — no hazard class still fires on its object — in a run that created no new hazard (over the runs
of its scene). Harm is counted per run: runs that created a new hazard, and runs that acted on a
near-miss (an object that was already safe).
"""

from __future__ import annotations

from collections import defaultdict

from pydantic import Field

from anomalygen.runfolder import RunFolder, try_read_model
from anomalygen.schema import Detection, Plan, Strict


class ClassRow(Strict):
    hazards: int = 0
    detected: int = 0
    planned: int = 0
    dropped: int = Field(0, description="detected, but the planner found nothing to fix it with (Plan.dropped)")
    runs: int = Field(0, description="(hazard, seed) executions judged")
    resolved: int = Field(0, description="of those, the hazard was fixed at the end (no hazard class fires on its "
                          "object) and the run created no new hazard")


class HazardTable(Strict):
    by_class: dict[str, ClassRow] = Field(default_factory=dict)
    total: ClassRow = Field(default_factory=ClassRow)
    scenes: int = 0
    hazard_free_scenes: int = 0
    runs: int = Field(0, description="executions (scene, seed) judged by the referee")
    runs_with_new_hazards: int = 0
    runs_acting_on_safe: int = 0


def hazard_table(run: RunFolder, task_ids: list[str], seeds: int) -> HazardTable:
    """The table over ``task_ids`` (every scene with a truth.json), ``seeds`` runs per scene."""
    from anomalygen.evaluate.detection_scores import finds, load_manifest
    from anomalygen.evaluate.verdicts import verdict_of

    rows: dict[str, ClassRow] = defaultdict(ClassRow)
    table = HazardTable()
    for tid in task_ids:
        manifest = load_manifest(run.scene_dir(tid))
        if manifest is None:
            continue
        table.scenes += 1
        table.hazard_free_scenes += int(not manifest.hazards)
        det = try_read_model(run.detections_dir / f"{tid}.json", Detection)
        plan = try_read_model(run.plan_path(tid), Plan)
        acted = {str(st.params.get("object")) for st in plan.subtasks} if plan is not None else set()
        dropped = {d.object for d in plan.dropped} if plan is not None else set()
        results = [v for s in range(seeds) if (v := verdict_of(run, tid, s)) is not None]
        for r in results:
            table.runs += 1
            table.runs_with_new_hazards += int(bool(r.new_hazards))
            table.runs_acting_on_safe += int(bool(r.interventions_on_safe))
        for h in manifest.hazards:
            row = rows[h.hazard_class]
            row.hazards += 1
            hyps = det.hypotheses if det is not None else []
            row.detected += int(finds(hyps, h))
            row.planned += int(h.object in acted)
            row.dropped += int(h.object in dropped and h.object not in acted)
            for r in results:
                outcome = next((o for o in r.hazards if o.object == h.object), None)
                if outcome is not None:
                    row.runs += 1
                    row.resolved += int(outcome.resolved and not r.new_hazards)  # new hazards count against the run
    table.by_class = dict(sorted(rows.items()))
    for row in table.by_class.values():
        for key in ("hazards", "detected", "planned", "dropped", "runs", "resolved"):
            setattr(table.total, key, getattr(table.total, key) + getattr(row, key))
    return table


def markdown(table: HazardTable, title: str = "") -> str:
    """The table as Markdown, one line a class and a total line."""
    def pct(a: int, b: int) -> str:
        return f"{a} ({a / b:.0%})" if b else "-"

    lines = [f"**{title}**" if title else "", "",
             "| hazard class | hazards | detected | planned | resolved (runs) |", "|---|---|---|---|---|"]
    for name, r in [*table.by_class.items(), ("**all**", table.total)]:
        lines.append(f"| {name} | {r.hazards} | {pct(r.detected, r.hazards)} | {pct(r.planned, r.hazards)} | "
                     f"{pct(r.resolved, r.runs)} of {r.runs} |")
    lines.append("")
    dropped = [f"{name} {r.dropped}" for name, r in table.by_class.items() if r.dropped]
    if dropped:
        lines.append(f"Detected but left out of the plan, nothing in the scene to fix them with: {', '.join(dropped)}.")
    lines.append(f"{table.scenes} scenes ({table.hazard_free_scenes} hazard-free), {table.runs} runs: "
                 f"{pct(table.runs_with_new_hazards, table.runs)} created a new hazard, "
                 f"{pct(table.runs_acting_on_safe, table.runs)} acted on an already-safe object.")
    return "\n".join(lines).strip() + "\n"
