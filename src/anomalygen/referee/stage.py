"""Stage "judge": after the robot's items have finished, the referee judges what they left behind.

Per task (one runner item), with the answer key at hand (the scene's ``truth.json``): every learn run
of the scene (``skills/<task>/seed<k>/``) has its final simulator state (``final_state.npz``) released
and settled and judged against the truth into ``verdict.json``, with the scene graph it was judged on
in ``judged_graph.json``. Runs from before the state was saved are judged on their
``final_graph.json`` as it was (``judged_from = "graph"``).

An item is done when every run has a verdict and its fingerprint (the scene, its truth, each run's
result and final state) is unchanged, so re-running learn or rebuilding the scene redoes the judging;
no setting does, as the judge reads none (``reads``). After the items: the fixes table by hazard
class — the referee's verdict, with the robot's own check beside it. (Detections are scored against
the truth on the evaluate side.)
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path
from typing import TYPE_CHECKING, Any

from anomalygen.runfolder import RunFolder, try_read_model, write_model
from anomalygen.runner import StageContext, StageSummary, check_only, run_items
from anomalygen.scene_files import (
    FINAL_GRAPH,
    FINAL_STATE,
    JUDGED_GRAPH,
    RESULT,
    SCENE_GRAPH,
    SCENE_SPEC,
    SCENE_XML,
    TRUTH,
    VERDICT,
)
from anomalygen.schema import SceneGraph, SceneSpec, SkillResult, TaskProposal, Verdict

if TYPE_CHECKING:
    from anomalygen.config import Settings

STAGE = "judge"
TABLE_COUNTS = ("runs", "robot_done", "judged", "resolved", "hazard_free", "no_action_needed", "acted_on_safe",
                "new_hazards", "on_safe")


def verdict_path(run: RunFolder, task_id: str, seed: int) -> Path:
    return run.skill_dir(task_id, seed) / VERDICT


def load_verdict(run: RunFolder | str | Path, task_id: str, seed: int) -> Verdict | None:
    """The referee's verdict on one learn run (``skills/<task>/seed<k>/verdict.json``), None if not judged."""
    folder = run if isinstance(run, RunFolder) else RunFolder(run)
    return try_read_model(verdict_path(folder, task_id, seed), Verdict)


def _seeds(run: RunFolder, task_id: str) -> list[int]:
    """Seeds with a learn result for the task."""
    root = run.skills_dir / task_id
    if not root.is_dir():
        return []
    return sorted(int(p.parent.name.removeprefix("seed")) for p in root.glob(f"seed*/{RESULT}")
                  if p.parent.name.removeprefix("seed").isdigit())


def _inputs(run: RunFolder, task_id: str) -> list[Path]:
    """What a task's verdicts are made from: the scene, its truth, and every run's result and end state."""

    scene = run.scene_dir(task_id)
    runs = [run.skill_dir(task_id, s) / name for s in _seeds(run, task_id)
            for name in (RESULT, FINAL_STATE, FINAL_GRAPH)]
    return [scene / SCENE_SPEC, scene / SCENE_XML, scene / TRUTH, *runs]


def judge_run(run: RunFolder, task_id: str, seed: int, spec: SceneSpec, manifest, kb, scene=None) -> Verdict | None:
    """The verdict on one learn run, from its saved final state (else its final graph); None without either.

    ``scene``: the (model, data) of the task's scene, loaded once per task and reused here."""
    from anomalygen.referee.settle import initial_graph, settled_graph
    from anomalygen.referee.verdict import verdict_on
    from anomalygen.world.state import restore_state

    folder = run.skill_dir(task_id, seed)
    if (folder / FINAL_STATE).is_file():
        model, data = scene
        restore_state(folder / FINAL_STATE, model, data)
        final, released, settled = settled_graph(model, data, spec)
        write_model(folder / JUDGED_GRAPH, final)
        return verdict_on(manifest, initial_graph(model, spec), final, kb, task_id=task_id, seed=seed,
                          released=released, settle_s=settled)
    initial = try_read_model(run.scene_dir(task_id) / SCENE_GRAPH, SceneGraph)
    final = try_read_model(folder / FINAL_GRAPH, SceneGraph)
    if initial is None or final is None:
        return None
    return verdict_on(manifest, initial, final, kb, task_id=task_id, seed=seed, judged_from="graph")


def judge_item(task_id: str, payload: dict[str, Any], ctx: StageContext) -> dict[str, Any]:
    from anomalygen.knowledge import load_kb
    from anomalygen.truth.manifest import load_manifest
    from anomalygen.world.graph import load_scene

    run = ctx.run
    scene_dir = run.scene_dir(task_id)
    spec = try_read_model(scene_dir / SCENE_SPEC, SceneSpec)
    manifest = load_manifest(scene_dir)
    seeds = _seeds(run, task_id)
    out: dict[str, Any] = {"verdicts": {}}
    if manifest is None or spec is None or not seeds:
        return out
    kb = load_kb()
    model, data, _ = load_scene(scene_dir)
    for seed in seeds:
        verdict = judge_run(run, task_id, seed, spec, manifest, kb, (model, data))
        if verdict is not None:
            write_model(verdict_path(run, task_id, seed), verdict)
            out["verdicts"][seed] = verdict.status
    return out


def _is_done_for(run: RunFolder):
    def is_done(task_id: str) -> bool:
        if not (run.scene_dir(task_id) / TRUTH).is_file():
            return True
        return all(verdict_path(run, task_id, s).is_file() for s in _seeds(run, task_id))
    return is_done


def verdict_table(run: RunFolder, tasks: list[TaskProposal]) -> dict[str, dict[str, float]]:
    """Per hazard class: learn runs; the referee's verdicts (``judged``: runs with a verdict; ``resolved``
    on scenes with hazards; ``hazard_free`` runs and of those ``no_action_needed`` / ``acted_on_safe``;
    runs that created a new hazard or acted on a near-miss); and, beside it, the robot's own check
    (``robot_done``)."""
    acc: dict[str, dict[str, int]] = defaultdict(lambda: dict.fromkeys(TABLE_COUNTS, 0))
    for t in tasks:
        for seed in _seeds(run, t.id):
            row = acc[t.hazard_class]
            res = try_read_model(run.skill_dir(t.id, seed) / RESULT, SkillResult)
            row["runs"] += 1
            row["robot_done"] += int(bool(res is not None and res.success))
            v = load_verdict(run, t.id, seed)
            if v is None:
                continue
            row["judged"] += 1
            row["resolved"] += int(v.resolved)
            row["hazard_free"] += int(not v.hazards)
            row["no_action_needed"] += int(v.status == "no_action_needed")
            row["acted_on_safe"] += int(v.status == "acted_on_safe")
            row["new_hazards"] += int(bool(v.new_hazards))
            row["on_safe"] += int(bool(v.interventions_on_safe))
    return {hc: dict(row) for hc, row in sorted(acc.items())}


def _print_table(table: dict[str, dict[str, float]]) -> None:
    from anomalygen.tables import name_table, print_with_total

    t = name_table("the referee's verdict by hazard class; free: hazard-free runs left alone/acted on; new: runs "
                   "that made a hazard; own: the robot's own check", "hazard class",
                   ("runs", "resolved", "free", "new", "on safe", "own"), [*table, "all"])

    def cells(name: str, row: dict) -> list[str]:
        with_hazards = row["judged"] - row["hazard_free"]
        free = row["hazard_free"]
        resolved = f"{row['resolved']}/{with_hazards}" if with_hazards else "-"
        return [name, str(row["runs"]), resolved, f"{row['no_action_needed']}/{row['acted_on_safe']}" if free else "-",
                str(row["new_hazards"]), str(row["on_safe"]), f"{row['robot_done']}/{row['runs']}"]

    print_with_total(t, table, TABLE_COUNTS, cells)


def reads(settings: Settings) -> None:
    """What a judge item reads of the settings (its fingerprint's config part): nothing. The referee
    judges from the files alone (the scene, its truth, each run's end state) with its own fixed
    settle, so no setting redoes a verdict; a changed input file does."""
    return None


def run_stage(run: RunFolder, settings: Settings, *, force: bool = False, only: list[str] | None = None) -> StageSummary:
    tasks = run.load_tasks()
    check_only(only, [t.id for t in tasks])
    chosen = [t for t in tasks if (not only or t.id in only) and (run.scene_dir(t.id) / SCENE_SPEC).is_file()]
    items = [(t.id, {}) for t in chosen]
    summary = run_items(run, STAGE, items, judge_item, settings=settings, is_done=_is_done_for(run), force=force,
                        description="judge", inputs=lambda task_id: _inputs(run, task_id), config=reads(settings))
    table = verdict_table(run, chosen)
    summary.results["by_class"] = table
    if not settings.quiet and table:
        _print_table(table)
    return summary
