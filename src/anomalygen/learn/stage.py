"""Stage 4b: execute every plan on its built scene, once per seed; writes ``skills/<task>/seed<k>/``.

Items are (task x seed) pairs for tasks that have both a plan and a built scene. Each item writes
``result.json`` (``schema.SkillResult``) and, with ``learn.video``, ``video.mp4``. An item is done
when its result.json validates, so a rerun resumes; one failing execution fails one item only.
At the end a success table by hazard class goes to stderr and into ``summary.results["by_class"]``.
"""

from __future__ import annotations

from collections import defaultdict
from typing import TYPE_CHECKING

from anomalygen.errors import ItemFailed
from anomalygen.runfolder import RunFolder, try_read_model, write_model
from anomalygen.runner import StageContext, StageSummary, run_items
from anomalygen.schema import Plan, SkillResult

if TYPE_CHECKING:
    from anomalygen.config import Settings

STAGE = "learn"


def _item_id(task_id: str, seed: int) -> str:
    return f"{task_id}@seed{seed}"


def _split(item_id: str) -> tuple[str, int]:
    task_id, seed = item_id.rsplit("@seed", 1)
    return task_id, int(seed)


def learn_item(item_id: str, payload: dict, ctx: StageContext) -> dict:
    from anomalygen.learn.execute import execute_plan

    run, settings = ctx.run, ctx.settings
    task_id, seed = _split(item_id)
    plan = try_read_model(run.plan_path(task_id), Plan)
    if plan is None:
        raise ItemFailed(f"no valid plan for {task_id}")
    out = run.skill_dir(task_id, seed)
    video = out / "video.mp4" if settings.learn.video else None
    result = execute_plan(run.scene_dir(task_id), plan, seed=seed, video_path=video,
                          sac_steps=settings.learn.sac_steps, retries=settings.learn.retries,
                          reward_mode=settings.learn.reward_mode)
    if result.video:
        result = result.model_copy(update={"video": "video.mp4"})
    write_model(out / "result.json", result)
    return {"success": result.success, "hazard_class": payload["hazard_class"]}


def success_table(run: RunFolder, items: list[tuple[str, dict]]) -> dict[str, dict[str, float]]:
    """Per hazard class: executions, successes, rate (from the result files on disk)."""
    acc: dict[str, list[int]] = defaultdict(lambda: [0, 0])
    for item_id, payload in items:
        task_id, seed = _split(item_id)
        res = try_read_model(run.skill_dir(task_id, seed) / "result.json", SkillResult)
        row = acc[payload["hazard_class"]]
        row[0] += 1
        row[1] += int(bool(res is not None and res.success))
    return {hc: {"n": n, "success": s, "rate": round(s / n, 3) if n else 0.0} for hc, (n, s) in sorted(acc.items())}


def _print_table(table: dict[str, dict[str, float]]) -> None:
    from rich.console import Console
    from rich.table import Table

    t = Table(title="skill success by hazard class")
    for col in ("hazard class", "runs", "success", "rate"):
        t.add_column(col, justify="left" if col == "hazard class" else "right")
    for hc, row in table.items():
        t.add_row(hc, str(row["n"]), str(row["success"]), f"{row['rate']:.0%}")
    n = sum(r["n"] for r in table.values())
    s = sum(r["success"] for r in table.values())
    t.add_row("all", str(n), str(s), f"{s / n:.0%}" if n else "-")
    Console(stderr=True).print(t)


def run_stage(run: RunFolder, settings: Settings, *, force: bool = False, only: list[str] | None = None) -> StageSummary:
    items: list[tuple[str, dict]] = []
    for t in run.load_tasks():
        if only and t.id not in only:
            continue
        if not run.plan_path(t.id).is_file() or not (run.scene_dir(t.id) / "scene.json").is_file():
            continue
        for seed in range(settings.learn.seeds):
            items.append((_item_id(t.id, seed), {"hazard_class": t.hazard_class}))

    def done(item_id: str) -> bool:
        task_id, seed = _split(item_id)
        return try_read_model(run.skill_dir(task_id, seed) / "result.json", SkillResult) is not None

    summary = run_items(run, STAGE, items, learn_item, settings=settings, is_done=done, force=force)
    table = success_table(run, items)
    summary.results["by_class"] = table
    if not settings.quiet and table:
        _print_table(table)
    return summary
