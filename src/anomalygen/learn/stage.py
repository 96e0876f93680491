"""Stage 4b: execute every plan on its built scene, once per seed; writes ``skills/<task>/seed<k>/``.

Items are (task x seed) pairs for tasks that have both a plan and a built scene. Each item writes
``result.json`` (``schema.SkillResult``: what the robot believes it achieved), the final state the
referee judges afterwards (``final_state.npz``; ``final_graph.json`` is the robot's perceived graph of
it) and, with ``learn.video``, ``video.mp4``. An item is done when its result.json validates, so a
rerun resumes; one failing execution fails one item only. At the end a table of the robot's own check
by hazard class goes to stderr and into ``summary.results["by_class"]``; whether the hazards are
really gone is the judge stage's verdict (``anomalygen judge``), which this stage never reads.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path
from typing import TYPE_CHECKING

from anomalygen.errors import ItemFailed
from anomalygen.runfolder import RunFolder, try_read_model, write_model
from anomalygen.runner import StageContext, StageSummary, check_only, config_section, run_items
from anomalygen.scene_files import FINAL_GRAPH, FINAL_STATE, RESULT, SCENE_GRAPH, SCENE_SPEC, SCENE_XML, VIDEO
from anomalygen.schema import Plan, SkillResult

if TYPE_CHECKING:
    from anomalygen.config import Settings

STAGE = "learn"


def run_item_id(task_id: str, seed: int) -> str:
    """``t0001-3fa2c1d9@seed0``: one execution of a task's scene (also a bench episode's item)."""
    return f"{task_id}@seed{seed}"


def split_run_item(item_id: str) -> tuple[str, int]:
    task_id, seed = item_id.rsplit("@seed", 1)
    return task_id, int(seed)


def learn_item(item_id: str, payload: dict, ctx: StageContext) -> dict:
    from anomalygen.learn.execute import execute_plan

    run, settings = ctx.run, ctx.settings
    task_id, seed = split_run_item(item_id)
    plan = try_read_model(run.plan_path(task_id), Plan)
    if plan is None:
        raise ItemFailed(f"no valid plan for {task_id}")
    out = run.skill_dir(task_id, seed)
    video = out / VIDEO if settings.learn.video else None
    final_graph = out / FINAL_GRAPH
    result = execute_plan(run.scene_dir(task_id), plan, seed=seed, video_path=video,
                          sac_steps=settings.learn.sac_steps, retries=settings.learn.retries,
                          reward_mode=settings.learn.reward_mode, final_graph_path=final_graph,
                          final_state_path=out / FINAL_STATE, n_envs=settings.learn.n_envs,
                          recheck_fixes=settings.plan.max_fixes if settings.learn.recheck else 0)
    if result.video:
        result = result.model_copy(update={"video": VIDEO})
    write_model(out / RESULT, result)
    return {"success": result.success}


def _inputs(run: RunFolder, task_id: str) -> list[Path]:
    """What an execution is made from: its plan and the built scene (a re-plan or rebuild redoes it)."""
    scene = run.scene_dir(task_id)
    return [run.plan_path(task_id), scene / SCENE_SPEC, scene / SCENE_XML, scene / SCENE_GRAPH]


def success_table(run: RunFolder, items: list[tuple[str, dict]], classes: dict[str, str]) -> dict[str, dict[str, float]]:
    """Per hazard class of the task (``classes``: task id -> class; the grouping is done here, after
    the items, which never see it): executions and the robot's own check (``success``: its plan's final
    condition held). Not the referee's verdict: that comes after this stage (``anomalygen judge``)."""
    acc: dict[str, dict[str, int]] = defaultdict(lambda: dict.fromkeys(TABLE_COUNTS, 0))
    for item_id, _payload in items:
        task_id, seed = split_run_item(item_id)
        res = try_read_model(run.skill_dir(task_id, seed) / RESULT, SkillResult)
        row = acc[classes.get(task_id, "unknown")]
        row["n"] += 1
        row["success"] += int(bool(res is not None and res.success))
    return {hc: {**row, "rate": round(row["success"] / row["n"], 3) if row["n"] else 0.0}
            for hc, row in sorted(acc.items())}


TABLE_COUNTS = ("n", "success")


def _print_table(table: dict[str, dict[str, float]]) -> None:
    from anomalygen.tables import name_table, print_with_total

    t = name_table("the robot's own check (its plan's final condition held) by hazard class; the referee's "
                   "verdict: anomalygen judge", "hazard class", ("runs", "own check"), [*table, "all"])

    def cells(name: str, row: dict) -> list[str]:
        n = row["n"]
        done = f"{row['success']} ({row['success'] / n:.0%})" if n else "-"
        return [name, str(n), done]

    print_with_total(t, table, TABLE_COUNTS, cells)


def reads(settings: Settings) -> dict:
    """What a learn item reads of the settings (its fingerprint's config part): ``[learn]`` less
    ``seeds`` (adding seeds runs only the new ones) and, with ``learn.recheck``, ``plan.max_fixes`` (how
    many hazards the look-again fixes). Not the master seed: an item's seed is its own."""
    return config_section(settings, "learn", exclude=("seeds",), seed=False,
                          also={"plan": ("max_fixes",)} if settings.learn.recheck else None)


def run_stage(run: RunFolder, settings: Settings, *, force: bool = False, only: list[str] | None = None) -> StageSummary:
    items: list[tuple[str, dict]] = []
    tasks = run.load_tasks()
    check_only(only, [t.id for t in tasks])
    for t in tasks:
        if only and t.id not in only:
            continue
        if not run.plan_path(t.id).is_file() or not (run.scene_dir(t.id) / SCENE_SPEC).is_file():
            continue
        for seed in range(settings.learn.seeds):
            items.append((run_item_id(t.id, seed), {}))

    def done(item_id: str) -> bool:
        task_id, seed = split_run_item(item_id)
        return try_read_model(run.skill_dir(task_id, seed) / RESULT, SkillResult) is not None

    summary = run_items(run, STAGE, items, learn_item, settings=settings, is_done=done, force=force,
                        inputs=lambda item_id: _inputs(run, split_run_item(item_id)[0]),
                        config=reads(settings))
    table = success_table(run, items, {t.id: t.hazard_class for t in tasks})
    summary.results["by_class"] = table
    if not settings.quiet and table:
        _print_table(table)
    return summary
