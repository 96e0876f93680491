"""``anomalygen bench``: run an agent over a suite in the skill-level env; the referee judges every episode.

Why a run folder: the bench is a stage like the others. Its folder (``--out``) is a run folder whose
``scenes`` is a link to the suite's and whose items are (scene, seed) episodes, run inline, in worker
processes or on Ray (``anomalygen.runner``), resumable, one failing episode recorded without stopping
the rest. Each episode writes, under ``skills/<task>/seed<k>/``:

- ``episode.json`` (``schema.EpisodeRecord``): every call the agent made, what the env read, the
  error or the sub-tasks it ran;
- ``final_state.npz`` and ``result.json``, as the learn stage writes them (the robot's own check is
  that every sub-task it ran passed its check), so ``anomalygen judge --run OUT`` judges the folder
  again from the saved states;
- ``verdict.json``: the referee's verdict the env's wrapper put in ``info`` at the end;

and ``detections/<task>.json`` when the agent reports what it detected. Then ``bench.json`` and
``bench.html`` hold the table (``bench/report.py``).
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from anomalygen.errors import UserError
from anomalygen.learn.stage import run_item_id, split_run_item
from anomalygen.runfolder import RunFolder, try_read_model, write_model
from anomalygen.runner import StageContext, config_section, run_items
from anomalygen.scene_files import EPISODE, FINAL_STATE, RESULT, SCENE_SPEC, SCENE_XML, TRUTH, VERDICT
from anomalygen.schema import (
    CallRecord,
    Detection,
    EpisodeRecord,
    Hypothesis,
    SkillResult,
    SubTaskResult,
    Verdict,
)

if TYPE_CHECKING:
    from anomalygen.bench.suites import Suite
    from anomalygen.config import Settings

STAGE = "bench"


def prepare(out: Path, suite: Suite, settings: Settings) -> RunFolder:
    """The bench's run folder: its ``scenes`` a link to the suite's, the suite's task list beside it."""
    run = RunFolder.create(out, settings=settings)
    target = RunFolder(suite.root).scenes_dir.resolve()
    if run.scenes_dir.is_symlink() or run.scenes_dir.exists():
        if run.scenes_dir.resolve() != target:
            raise UserError(f"{out} already holds the scenes of another suite ({run.scenes_dir.resolve()}); "
                            "use another --out")
    else:
        os.symlink(target, run.scenes_dir, target_is_directory=True)
    tasks = RunFolder(suite.root).tasks_path
    if tasks.is_file() and not run.tasks_path.is_file():
        run.tasks_path.write_bytes(tasks.read_bytes())
    return run


def bench_item(item_id: str, payload: dict[str, Any], ctx: StageContext) -> dict[str, Any]:
    """One episode of the agent on one scene, judged."""
    from anomalygen import make_env
    from anomalygen.agents.base import load_agent, make_agent
    from anomalygen.world.state import save_state

    run = ctx.run
    task_id, seed = split_run_item(item_id)
    agent = make_agent(load_agent(payload["agent"]), ctx.settings, **payload.get("options", {}))
    env = make_env(run.scene_dir(task_id), level="skills", observe=tuple(getattr(agent, "observe", ())),
                   max_calls=payload["max_calls"], settings=ctx.settings)
    t0 = time.perf_counter()
    try:
        obs, info = env.reset(seed=seed)
        agent.reset(obs, info)
        calls: list[CallRecord] = []
        while True:
            ts = time.perf_counter()
            action = agent.act(obs)
            obs, _reward, terminated, truncated, info = env.step(action)
            if callable(getattr(agent, "result", None)):
                agent.result(info)
            calls.append(CallRecord(action=_text(action), call=info["call"], error=info["error"],
                                    executed=[SubTaskResult.model_validate(r) for r in info["executed"]],
                                    control_steps=info["control_steps"], wall_s=round(time.perf_counter() - ts, 3)))
            if terminated or truncated:
                break
        base = env.unwrapped
        out = run.skill_dir(task_id, seed)
        save_state(out / FINAL_STATE, base.model, base.data)
        verdict: Verdict = info["verdict"].model_copy(update={"task_id": task_id, "seed": seed})
        ended = "done" if terminated else "budget"
        write_model(out / EPISODE, EpisodeRecord(task_id=task_id, seed=seed, agent=payload["agent"], calls=calls,
                                                 ended=ended, wall_s=round(time.perf_counter() - t0, 3)))
        subtasks = [st for c in calls for st in c.executed]
        write_model(out / RESULT, SkillResult(task_id=task_id, seed=seed, subtasks=subtasks,
                                              success=bool(subtasks) and all(st.success for st in subtasks),
                                              timings={"execute_s": round(time.perf_counter() - t0, 3),
                                                       "control_steps": float(base.episode.steps)}))
        write_model(out / VERDICT, verdict)
        _write_detection(run, task_id, seed, agent)
    finally:
        env.close()
    return {"status": verdict.status, "calls": len(calls), "invalid": sum(c.error is not None for c in calls)}


def _text(action) -> str:
    text = action.text() if hasattr(action, "text") else str(action)
    return text[:2000]


def _write_detection(run: RunFolder, task_id: str, seed: int, agent) -> None:
    """What the agent says it detected (first seed only: one detection per scene, as the detect stage)."""
    report = agent.detections() if callable(getattr(agent, "detections", None)) else None
    if report is None or seed != 0:
        return
    if not isinstance(report, Detection):
        hyps = [h if isinstance(h, Hypothesis) else Hypothesis.model_validate(h) for h in report]
        report = Detection(task_id=task_id, scene_id=task_id, detector="agent", hypotheses=hyps)
    write_model(run.detections_dir / f"{task_id}.json", report.model_copy(update={"task_id": task_id}))


def run_bench(agent: str, suite: Suite, out: Path, settings: Settings, *, seeds: int = 1,
              max_calls: int | None = None, options: dict | None = None, only: list[str] | None = None,
              force: bool = False):
    """Every (scene, seed) episode of the agent on the suite, then the report; returns the BenchReport."""
    from anomalygen.agents.base import load_agent
    from anomalygen.agents.skill_env import MAX_CALLS
    from anomalygen.bench.report import write_report
    from anomalygen.runner import check_only

    load_agent(agent)  # a bad MODULE:CLASS is the user's error, before any worker starts
    run = prepare(out, suite, settings)
    check_only(only, suite.task_ids)
    ids = [t for t in suite.task_ids if not only or t in only]
    payload = {"agent": agent, "options": options or {}, "max_calls": max_calls or MAX_CALLS}
    items = [(run_item_id(t, k), payload) for t in ids for k in range(seeds)]

    def done(item_id: str) -> bool:
        task_id, seed = split_run_item(item_id)
        return try_read_model(run.skill_dir(task_id, seed) / VERDICT, Verdict) is not None

    def inputs(item_id: str) -> list[Path]:
        scene = run.scene_dir(split_run_item(item_id)[0])
        return [scene / SCENE_SPEC, scene / SCENE_XML, scene / TRUTH]

    summary = run_items(run, STAGE, items, bench_item, settings=settings, is_done=done, force=force,
                        description=f"bench {agent}", inputs=inputs,
                        config=[config_section(settings, "detect"), config_section(settings, "plan"),
                                config_section(settings, "learn", exclude=("seeds", "video"))])  # the env records no video
    return write_report(run, agent, suite, ids, seeds, errors=summary.errors)

