"""Run one plan on its built scene: loop over its sub-tasks, ask the skill registry, retry, fall back.

All sub-tasks run in one :class:`~anomalygen.skills.episode.Episode`, so the state flows from one
step to the next (a grasp is followed by a move with the object still held) and what a skill opened
is remembered when a later one shuts it. Each sub-task goes to the skill the registry gives for its
method and action (:func:`~anomalygen.skills.registry.skill_for`). A sub-task succeeds when its
SuccessSpec holds on ``scene_graph`` right after it (or, with an empty spec, when the skill reports
success); the task succeeds when the plan's SuccessSpec holds on the final, settled state.

A primitive sub-task whose check fails is run again (``retries``). A SAC sub-task is learned on the
spot (``sac_steps`` environment steps from the state the plan has reached, then the best policy is
replayed); when it fails, cannot start, or its result does not last, the primitive of the same action
runs in its place. Each result records the skill that actually executed the sub-task
(``SubTaskResult.executed_by``). CEM sub-tasks need a legged robot, which household scenes do not
carry, and are reported as not executed with that reason.
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING

from anomalygen.schema import Plan, PredicateResult, SkillMethod, SkillResult, SubTask, SubTaskResult
from anomalygen.world.perception import load_perceived_scene
from anomalygen.world.state import save_state

if TYPE_CHECKING:  # pragma: no cover
    from anomalygen.skills.episode import Episode
    from anomalygen.skills.registry import SkillOutcome

CEM_NOT_EXECUTED = ("not executed: CEM plans the motion of a legged robot (the Gymnasium Ant); household "
                    "scenes carry the wheeled arm")
SAC_OFF = "not executed: sac_steps is 0"
#: Control steps the scene settles after the plan (before the robot looks again) and at the end, before
#: the final state is saved; the skill-level env (``anomalygen.agents``) settles as many on ``wait`` and ``done``.
FINAL_SETTLE_STEPS = 25  # a SAC skill that did not run: no primitive runs in its place

def _evaluate(calls, ep: Episode, bindings) -> list[PredicateResult]:
    from anomalygen.knowledge.predicates import evaluate_all

    return evaluate_all(list(calls), ep.graph(), bindings)


def execute_plan(scene_dir: str | Path, plan: Plan, *, seed: int, video_path: str | Path | None = None,
                 max_wall_s: float | None = None, sac_steps: int = 0, isolate: bool = True,
                 retries: int = 1, reward_mode: str = "spec",
                 final_graph_path: str | Path | None = None, n_envs: int = 1, recheck_fixes: int = 0,
                 final_state_path: str | Path | None = None) -> SkillResult:
    """Load the scene, run the plan's sub-tasks in order, check success, optionally record a video.

    Execution is closed-loop: a primitive sub-task whose success check fails on the scene right after
    it is run again, up to ``retries`` times, from the state it left (a camera set down 2 cm too near
    the edge is picked up and set down again; a door that sprang back is pushed again). The check is
    the sub-task's own SuccessSpec, evaluated on the scene graph the robot perceives.

    With ``isolate`` (default) the execution runs in a fresh process, so native code that crashes or
    leaks takes only the item with it. Its plans do not depend on the process: OMPL's random generator
    is process-global, and every Episode restarts its seed sequence at the episode's own seed
    (:func:`~anomalygen.robot.motion.restart_seed_sequence`), so the result is a function of (scene,
    plan, seed) alone, whichever worker or test runs it. Costs about a second. No decision
    depends on wall time: the episode stops starting sub-tasks after
    :data:`~anomalygen.skills.episode.EPISODE_MAX_STEPS` control steps; ``max_wall_s`` (default
    :data:`~anomalygen.skills.episode.EPISODE_WALL_CAP_S`) is only a safety net against a hung item.

    ``reward_mode`` is ``learn.reward_mode``: "code" trains SAC sub-tasks on sandboxed reward code
    (:func:`~anomalygen.skills.learned.sac_subtask.run_sac_subtask`).

    ``final_graph_path`` receives the scene graph of the final, settled state as the robot perceives it;
    ``final_state_path`` the simulator state itself (``scene.state``), which the referee's judge stage
    releases, settles and judges against the hidden truth (the robot's own verdict is ``success``).

    ``recheck_fixes`` > 0: after the plan the robot looks again and fixes up to that many hazards its
    own actions created (:mod:`anomalygen.learn.recheck`); their steps are listed with ids ``recheck_*``.
    """
    if isolate:
        from anomalygen.procs import child_pool

        with child_pool(1) as pool:
            return pool.submit(_execute_here, str(scene_dir), plan, seed, None if video_path is None else
                               str(video_path), max_wall_s, sac_steps, retries, reward_mode,
                               None if final_graph_path is None else str(final_graph_path), n_envs,
                               recheck_fixes, None if final_state_path is None else str(final_state_path)).result()
    return _execute_here(scene_dir, plan, seed, video_path, max_wall_s, sac_steps, retries, reward_mode,
                         final_graph_path, n_envs, recheck_fixes, final_state_path)


def _look_again(ep: Episode, before, plan: Plan, max_fixes: int, retries: int) -> list[SubTaskResult]:
    """One pass of :mod:`anomalygen.learn.recheck`: fix the hazards the plan's actions created."""
    from anomalygen.knowledge import load_kb
    from anomalygen.learn.recheck import new_hazards, repair_plan, spec_as_it_stands

    kb = load_kb()
    after = ep.graph()
    found = new_hazards(before, after, kb)
    if not found:
        return []
    repair, problems = repair_plan(plan.task_id, found, after, spec_as_it_stands(ep.spec, after), kb,
                                   max_fixes=max_fixes)
    out = [SubTaskResult(id=f"recheck_{cls}", method=SkillMethod.PRIMITIVE, success=False,
                         detail=f"seen after the plan, cannot fix: {why}") for cls, why in problems]
    return (run_subtasks(ep, repair, retries) if repair is not None else []) + out


def _run_skill(ep: Episode, st: SubTask, method: str) -> tuple[SkillOutcome, str | None]:
    """(outcome, ``method:action`` of the skill that ran) for one run of ``st`` by a ``method`` skill;
    a sub-task no skill is registered for fails with the registry's reason and no skill."""
    from anomalygen.skills.catalogue import SkillOutcome, UnknownSkill, lookup, skill_for

    try:
        skill = skill_for(ep, st) if method == str(st.method) else lookup(method, st.primitive or "")
    except UnknownSkill as exc:
        return SkillOutcome(False, 0, str(exc)), None
    return skill().run(ep, st), skill.key()


def _run_once(ep: Episode, st: SubTask, plan: Plan) -> tuple[SkillOutcome, str | None]:
    """One execution of ``st``; a SAC sub-task that fails gives way to the primitive of its action."""
    from anomalygen.skills.catalogue import SkillOutcome

    res, by = _run_skill(ep, st, str(st.method))
    if st.method != SkillMethod.SAC:
        return res, by
    ep.settle(10)
    held = res.success and all(p.holds for p in _evaluate(st.success.predicates, ep, plan.bindings))
    if not held and st.primitive and not res.detail.startswith(SAC_OFF):
        # the learned policy failed, could not start, or its result did not last: the primitive behind
        # the step gets its turn, and the result says both what SAC did and that it fell back
        if res.success:
            res.detail += "; its check failed afterwards"
        prim, by = _run_skill(ep, st, SkillMethod.PRIMITIVE.value)
        res = SkillOutcome(prim.success, res.steps + prim.steps,
                           f"SAC failed ({res.detail}); fell back to the {st.primitive} primitive: {prim.detail}")
    return res, by


def run_subtasks(ep: Episode, plan: Plan, retries: int = 1) -> list[SubTaskResult]:
    """Run ``plan``'s sub-tasks in order in the episode; one SubTaskResult each."""
    ep.plan = plan  # skills resolve role variables through the plan being run
    results: list[SubTaskResult] = []
    for st in plan.subtasks:
        ts = time.perf_counter()
        if st.method == SkillMethod.CEM:
            results.append(SubTaskResult(id=st.id, method=st.method, success=False, detail=CEM_NOT_EXECUTED))
            continue
        if why := ep.budget.spent(ep.steps):
            results.append(SubTaskResult(id=st.id, method=st.method, success=False, detail=f"not executed: {why}"))
            continue
        s0 = ep.steps
        details: list[str] = []
        for attempt in range(1, 2 + (retries if st.method == SkillMethod.PRIMITIVE else 0)):
            res, by = _run_once(ep, st, plan)
            ep.settle(10)
            ep.come_to_rest()  # judge the state that lasts, not a plate still toppling off its shelf
            ok = res.success
            detail = res.detail
            if st.success.predicates:
                preds = _evaluate(st.success.predicates, ep, plan.bindings)
                ok = all(p.holds for p in preds)
                detail += "; " + "; ".join(f"{'not ' if p.call.negate else ''}{p.call.name}: {'yes' if p.holds else 'no'}" for p in preds)
            details.append(detail if attempt == 1 else f"attempt {attempt}: {detail}")
            if ok or ep.budget.spent(ep.steps):
                break
        executed = None if by is None or res.detail.startswith("not executed") else by
        results.append(SubTaskResult(id=st.id, method=st.method, success=ok, steps=ep.steps - s0,
                                     wall_s=round(time.perf_counter() - ts, 3), detail=" | ".join(details),
                                     attempts=attempt, executed_by=executed))
    return results


def _execute_here(scene_dir, plan: Plan, seed: int, video_path, max_wall_s: float | None, sac_steps: int,
                  retries: int = 1, reward_mode: str = "spec", final_graph_path=None, n_envs: int = 1,
                  recheck_fixes: int = 0, final_state_path=None) -> SkillResult:
    from anomalygen.rng import item_rng
    from anomalygen.skills.episode import Episode, EpisodeBudget, LearningSettings

    budget = EpisodeBudget() if max_wall_s is None else EpisodeBudget(seconds=max_wall_s)
    model, data, spec = load_perceived_scene(scene_dir)  # what it perceives: no bindings, roles or task
    timings = {"load_s": round(budget.elapsed(), 3)}
    rec = None
    if video_path is not None:
        from anomalygen.skills.video import VideoRecorder

        rec = VideoRecorder(model)
    ep = Episode(model, data, spec, seed=seed, rng=item_rng(seed, plan.task_id), plan=plan, budget=budget,
                 learning=LearningSettings(sac_steps=sac_steps, reward_mode=reward_mode, n_envs=n_envs), video=rec)
    before = ep.graph() if recheck_fixes else None

    results = run_subtasks(ep, plan, retries)
    if before is not None and plan.subtasks:
        ep.settle(FINAL_SETTLE_STEPS)
        results += _look_again(ep, before, plan, recheck_fixes, retries)

    ep.settle(FINAL_SETTLE_STEPS)
    final = _evaluate(plan.success.predicates, ep, plan.bindings)
    if final_graph_path is not None:
        from anomalygen.runfolder import write_model

        write_model(Path(final_graph_path), ep.graph())
    if final_state_path is not None:

        save_state(final_state_path, ep.model, ep.data)
    timings["execute_s"] = round(budget.elapsed() - timings["load_s"], 3)
    timings["control_steps"] = float(ep.steps)
    video = None
    if rec is not None:
        rec.capture(data, force=True)
        tv = time.perf_counter()
        saved = rec.save(Path(video_path))
        rec.close()
        video = str(saved) if saved else None
        timings["video_s"] = round(time.perf_counter() - tv, 3)
    # an empty plan (nothing detected) is done by leaving the scene alone
    success = all(p.holds for p in final) if final else not plan.subtasks
    return SkillResult(task_id=plan.task_id, seed=seed, success=success, subtasks=results,
                       final_predicates=final, video=video, timings=timings)
