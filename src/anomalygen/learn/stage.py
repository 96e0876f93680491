"""Stage 4b: execute every plan on its built scene, once per seed; writes ``skills/<task>/seed<k>/``.

Items are (task x seed) pairs for tasks that have both a plan and a built scene. Each item writes
``result.json`` (``schema.SkillResult``) and, with ``learn.video``, ``video.mp4``. An item is done
when its result.json validates, so a rerun resumes; one failing execution fails one item only.
At the end a success table by hazard class goes to stderr and into ``summary.results["by_class"]``.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path
from typing import TYPE_CHECKING

from anomalygen.errors import ItemFailed
from anomalygen.runfolder import RunFolder, try_read_model, write_model
from anomalygen.runner import StageContext, StageSummary, check_only, config_section, run_items
from anomalygen.schema import FixOutcome, Plan, SceneGraph, SkillResult

if TYPE_CHECKING:
    from anomalygen.config import Settings

STAGE = "learn"
FINAL_GRAPH = "final_graph.json"  # the scene graph after execution, for the referee


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
    final_graph = out / FINAL_GRAPH
    result = execute_plan(run.scene_dir(task_id), plan, seed=seed, video_path=video,
                          sac_steps=settings.learn.sac_steps, retries=settings.learn.retries,
                          reward_mode=settings.learn.reward_mode, final_graph_path=final_graph,
                          n_envs=settings.learn.n_envs,
                          recheck_fixes=settings.learn.max_fixes if settings.learn.recheck else 0)
    if result.video:
        result = result.model_copy(update={"video": "video.mp4"})
    result = result.model_copy(update={"outcome": referee_verdict(run.scene_dir(task_id), final_graph)})
    write_model(out / "result.json", result)
    return {"success": result.success, "hazard_class": payload["hazard_class"]}


def referee_verdict(scene_dir, final_graph_path) -> FixOutcome | None:
    """The hidden-truth verdict, after the robot has finished (None for a scene without truth.json)."""
    from anomalygen.evaluate.referee import judge_fix
    from anomalygen.knowledge import load_kb
    from anomalygen.scene.truth import load_manifest

    manifest = load_manifest(scene_dir)
    initial = try_read_model(Path(scene_dir) / "scene_graph.json", SceneGraph)
    final = try_read_model(Path(final_graph_path), SceneGraph)
    if manifest is None or initial is None or final is None:
        return None
    return judge_fix(manifest, initial, final, load_kb())


def _inputs(run: RunFolder, task_id: str) -> list[Path]:
    """What an execution is made from: its plan and the built scene (a re-plan or rebuild redoes it)."""
    scene = run.scene_dir(task_id)
    return [run.plan_path(task_id), scene / "scene.json", scene / "scene.xml", scene / "scene_graph.json"]


def success_table(run: RunFolder, items: list[tuple[str, dict]]) -> dict[str, dict[str, float]]:
    """Per hazard class: executions; the robot's own verdict (``success``); the referee's verdict
    against the hidden truth (``resolved``, over the runs that have a truth manifest, ``judged``);
    and the harm done (``new_hazards``, ``on_safe``: runs that acted on a near-miss)."""
    acc: dict[str, dict[str, int]] = defaultdict(lambda: dict.fromkeys(TABLE_COUNTS, 0))
    for item_id, payload in items:
        task_id, seed = _split(item_id)
        res = try_read_model(run.skill_dir(task_id, seed) / "result.json", SkillResult)
        row = acc[payload["hazard_class"]]
        row["n"] += 1
        row["success"] += int(bool(res is not None and res.success))
        if res is not None and res.outcome is not None:
            row["judged"] += 1
            row["resolved"] += int(res.outcome.resolved)
            row["new_hazards"] += int(bool(res.outcome.new_hazards))
            row["on_safe"] += int(bool(res.outcome.interventions_on_safe))
    table: dict[str, dict[str, float]] = {}
    for hc, row in sorted(acc.items()):
        table[hc] = {**row, "rate": round(row["success"] / row["n"], 3) if row["n"] else 0.0,
                     "resolved_rate": round(row["resolved"] / row["judged"], 3) if row["judged"] else 0.0}
    return table


TABLE_COUNTS = ("n", "success", "judged", "resolved", "new_hazards", "on_safe")


def _print_table(table: dict[str, dict[str, float]]) -> None:
    from rich.console import Console

    from anomalygen.tables import name_table

    t = name_table("fixes by hazard class (robot's verdict vs the hidden truth)", "hazard class",
                   ("runs", "robot: done", "truth: resolved", "new hazards", "acted on safe"), [*table, "all"])

    def cells(name: str, row: dict) -> list[str]:
        n, judged = row["n"], row["judged"]
        done = f"{row['success']} ({row['success'] / n:.0%})" if n else "-"
        resolved = f"{row['resolved']}/{judged} ({row['resolved'] / judged:.0%})" if judged else "no truth"
        return [name, str(n), done, resolved, str(row["new_hazards"]), str(row["on_safe"])]

    for hc, row in table.items():
        t.add_row(*cells(hc, row))
    total = {k: sum(r[k] for r in table.values()) for k in TABLE_COUNTS}
    t.add_row(*cells("all", total))
    Console(stderr=True).print(t)


def run_stage(run: RunFolder, settings: Settings, *, force: bool = False, only: list[str] | None = None) -> StageSummary:
    items: list[tuple[str, dict]] = []
    tasks = run.load_tasks()
    check_only(only, [t.id for t in tasks])
    for t in tasks:
        if only and t.id not in only:
            continue
        if not run.plan_path(t.id).is_file() or not (run.scene_dir(t.id) / "scene.json").is_file():
            continue
        for seed in range(settings.learn.seeds):
            items.append((_item_id(t.id, seed), {"hazard_class": t.hazard_class}))

    def done(item_id: str) -> bool:
        task_id, seed = _split(item_id)
        return try_read_model(run.skill_dir(task_id, seed) / "result.json", SkillResult) is not None

    summary = run_items(run, STAGE, items, learn_item, settings=settings, is_done=done, force=force,
                        inputs=lambda item_id: _inputs(run, _split(item_id)[0]),
                        config=config_section(settings, "learn", exclude=("seeds",)))
    table = success_table(run, items)
    summary.results["by_class"] = table
    if not settings.quiet and table:
        _print_table(table)
    return summary
