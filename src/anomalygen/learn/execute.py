"""Run one plan on its built scene: each sub-task by its method, success checked on the scene graph.

Primitive sub-tasks are executed by :mod:`anomalygen.control.primitives` on one shared
:class:`~anomalygen.control.driver.Driver`, so the state flows from one step to the next (a grasp
is followed by a move with the object still held). A sub-task succeeds when its SuccessSpec holds on
``scene_graph`` right after it (or, with an empty spec, when the primitive reports success); the task
succeeds when the plan's SuccessSpec holds on the final, settled state. SAC sub-tasks are learned on
the spot (``sac_subtask.run_sac_subtask``: ``sac_steps`` environment steps from the state the plan has
reached, then the best policy is replayed on the Driver); CEM sub-tasks need a legged robot, which
household scenes do not carry, and are reported as not executed with that reason.
"""

from __future__ import annotations

import time
from pathlib import Path

from anomalygen.control.driver import PrimitiveResult
from anomalygen.control.geometry import surface_centre_of
from anomalygen.schema import (
    ENCLOSING_LABELS,
    Plan,
    PredicateResult,
    SkillMethod,
    SkillResult,
    SubTask,
    SubTaskResult,
)

ACCESS_LABELS = (*ENCLOSING_LABELS, "flap")  # parts that open a way into a container
NEARLY_CLOSED_TOL = 0.1  # open fraction under which a part still blocks the way in
OPEN_FRACTION = 0.6  # how far an opened part goes unless the recipe says (a window for air: a crack)


def _joint_for(spec, obj: str, part: str | None) -> tuple[str | None, float | None]:
    for o in spec.objects:
        if o.name == obj:
            states = [j for j in o.joint_states if part is None or j.label == part] or list(o.joint_states)
            if states:
                return states[0].name, states[0].closed_value
    return None, None


def _label_of(st: SubTask, prm: dict) -> str | None:
    """The part label the step is about: its ``part`` param, else the label its success predicate names."""
    if prm.get("part"):
        return str(prm["part"])
    for call in st.success.predicates:
        if "label" in call.args:
            return str(call.args["label"])
    return None


def _drive_joints(drv, st: SubTask, obj: str, prim: str, prm: dict):
    """Close (or open) every part of ``obj`` with the step's label, most open first.

    The planner names the object's first joint, but a fridge has a freezer and a main door and either
    may be the open one; the scene state says which to push, so the joints are re-chosen here.
    """
    from anomalygen.control.parts import actuate_part

    label = _label_of(st, prm)
    opening = prim in ("pull", "open_joint")
    cands = []
    for o in drv.spec.objects:
        if o.name != obj:
            continue
        for js in o.joint_states:
            if label is not None and js.label not in label.split("|") and js.name != prm.get("joint"):
                continue
            lo, hi = js.range
            closed = js.closed_value
            far = hi if abs(hi - closed) > abs(lo - closed) else lo
            goal = far if opening else closed
            gap = abs(float(drv.data.joint(js.name).qpos[0]) - goal) / max(abs(hi - lo), 1e-6)
            fraction = float(prm.get("open_fraction", OPEN_FRACTION))
            cands.append((gap, js.name, closed + fraction * (far - closed) if opening else goal, closed,
                          0.025 * abs(hi - lo)))
    if not cands and prm.get("joint") is not None:
        cands = [(1.0, str(prm["joint"]), float(prm.get("target", 0.0)), 0.0, 0.02)]
    if not cands:
        return PrimitiveResult(False, 0, f"{obj} has no articulated part labelled {label!r} to {prim}")
    cands.sort(key=lambda c: -c[0])
    steps, details = 0, {}
    for _ in range(2):  # a second pass: closing one door can knock a neighbour open again
        for _, joint, goal, closed, tol in cands:
            if abs(float(drv.data.joint(joint).qpos[0]) - goal) <= tol:  # done already (pushed along by another)
                continue
            r = actuate_part(drv, joint, goal, closed=closed, tol=tol)
            steps += r.steps
            details[joint] = r.detail
    ok = all(abs(float(drv.data.joint(j).qpos[0]) - g) <= t for _, j, g, _, t in cands)
    return PrimitiveResult(ok, steps, "; ".join(details.values()) or f"{label} parts of {obj} already there")


def _closed_parts(drv, name: str) -> list[str]:
    """Labels of the object's lids, doors, flaps and drawers that are (nearly) closed right now."""
    out = []
    for o in drv.spec.objects:
        if o.name == name:
            for js in o.joint_states:
                if js.label in ACCESS_LABELS and js.is_closed(NEARLY_CLOSED_TOL, float(drv.data.joint(js.name).qpos[0])):
                    out.append(js.label)
    return sorted(set(out))


def run_subtask(drv, st: SubTask, plan: Plan):
    """Execute one primitive sub-task on the driver; returns a PrimitiveResult."""
    from anomalygen.control import primitives as P

    prm = dict(st.params)
    obj = str(prm.get("object", plan.bindings.get("$hazard", "")))
    prim = st.primitive or ""
    if prim in ("grasp", "pick"):
        return P.grasp(drv, obj, lift=float(prm.get("lift", 0.12)))
    if prim == "approach":
        return P.approach(drv, obj)
    if prim == "release":
        return P.release(drv)
    if prim in ("move_to", "place_inside", "place_on"):
        region = str(prm.get("region") or prm.get("container") or prm.get("support") or "")
        if region == "surface_centre":
            region = surface_centre_of(drv, obj) or ""
            if not region:
                return PrimitiveResult(False, 0, f"{obj} stands on no support to re-centre it on")
        if drv.held != obj:  # move_to without a preceding grasp (move_away_from_edge): pick first
            g = P.grasp(drv, obj)
            if not g.success:
                return g
        into = any(c.name == "inside" and not c.negate for c in st.success.predicates) or prim == "place_inside"
        res = P.move_to(drv, obj, region, release_after=bool(prm.get("release", True)), into=into)
        shut = [lab for lab in _closed_parts(drv, region) if lab != "door" or not drv.opened.get(region)]
        if shut and into and not drv.opened.get(region):  # say why an 'inside' will fail
            res.detail += f"; {region}'s {', '.join(shut)} closed and the plan did not open it"
        return res
    if prim == "push_to":  # slide a free object over the floor beside a piece of furniture
        from anomalygen.control.push import push_to

        return push_to(drv, obj, str(prm.get("region") or prm.get("support") or ""))
    if prim == "take_out_of":  # lift it out of a container or appliance; it stays held
        from anomalygen.control.transfer import take_out_of

        return take_out_of(drv, obj, str(prm.get("region") or prm.get("container") or ""))
    if prim in ("close_lid", "open_lid"):  # every lid or flap of a portable container
        prm.setdefault("part", "lid|flap")
        return _drive_joints(drv, st, obj, "push" if prim == "close_lid" else "pull", prm)
    if prim in ("push", "pull") and prm.get("access"):  # open a container to put something in / shut it again
        from anomalygen.control import access

        if prim == "pull":
            return access.open_for_access(drv, obj, str(prm.get("part", "lid")).split("|"), prm.get("contents"))
        return access.close_opened(drv, obj, every=bool(prm.get("contents")))
    if prim in ("push", "pull", "close_joint", "open_joint", "switch_off"):
        return _drive_joints(drv, st, obj, prim, prm)
    return PrimitiveResult(False, 0, f"primitive {prim!r} is not implemented")


def _evaluate(calls, model, data, spec, bindings) -> list[PredicateResult]:
    from anomalygen.knowledge.predicates import evaluate_all
    from anomalygen.scene.graph import scene_graph

    return evaluate_all(list(calls), scene_graph(model, data, spec), bindings)


def execute_plan(scene_dir: str | Path, plan: Plan, *, seed: int, video_path: str | Path | None = None,
                 max_wall_s: float = 600.0, sac_steps: int = 0, isolate: bool = True,
                 retries: int = 1, reward_mode: str = "spec",
                 final_graph_path: str | Path | None = None, n_envs: int = 1, recheck_fixes: int = 0) -> SkillResult:
    """Load the scene, run the plan's sub-tasks in order, check success, optionally record a video.

    Execution is closed-loop: a primitive sub-task whose success check fails on the scene right after
    it is run again, up to ``retries`` times, from the state it left (a camera set down 2 cm too near
    the edge is picked up and set down again; a door that sprang back is pushed again). The check is
    the sub-task's own SuccessSpec, evaluated on the scene graph the robot perceives.

    With ``isolate`` (default) the execution runs in a fresh process: OMPL's random generator is
    process-global and seeded once, so a path planned in a process that has planned before depends on
    that history. In a fresh process the first seed is the item's, and the result is a function of
    (scene, plan, seed) alone, whichever worker or test runs it. Costs about a second.

    ``reward_mode`` is ``learn.reward_mode``: "code" trains SAC sub-tasks on sandboxed reward code
    (:func:`~anomalygen.rl.sac_subtask.run_sac_subtask`).

    ``final_graph_path`` receives the scene graph of the final, settled state: what the referee
    judges against the hidden truth (the robot's own verdict is ``success``).

    ``recheck_fixes`` > 0: after the plan the robot looks again and fixes up to that many hazards its
    own actions created (:mod:`anomalygen.learn.recheck`); their steps are listed with ids ``recheck_*``.
    """
    if isolate:
        from anomalygen.procs import child_pool

        with child_pool(1) as pool:
            return pool.submit(_execute_here, str(scene_dir), plan, seed, None if video_path is None else
                               str(video_path), max_wall_s, sac_steps, retries, reward_mode,
                               None if final_graph_path is None else str(final_graph_path), n_envs,
                               recheck_fixes).result()
    return _execute_here(scene_dir, plan, seed, video_path, max_wall_s, sac_steps, retries, reward_mode,
                         final_graph_path, n_envs, recheck_fixes)


def _look_again(drv, before, plan: Plan, max_fixes: int, run_steps) -> list[SubTaskResult]:
    """One pass of :mod:`anomalygen.learn.recheck`: fix the hazards the plan's actions created."""
    from anomalygen.knowledge import load_kb
    from anomalygen.learn.recheck import new_hazards, repair_plan, spec_as_it_stands
    from anomalygen.scene.graph import scene_graph

    kb = load_kb()
    after = scene_graph(drv.model, drv.data, drv.spec)
    found = new_hazards(before, after, kb)
    if not found:
        return []
    repair, problems = repair_plan(plan.task_id, found, after, spec_as_it_stands(drv.spec, after), kb,
                                   max_fixes=max_fixes)
    out = [SubTaskResult(id=f"recheck_{cls}", method=SkillMethod.PRIMITIVE, success=False,
                         detail=f"seen after the plan, cannot fix: {why}") for cls, why in problems]
    return (run_steps(repair.subtasks, repair) if repair is not None else []) + out


def _execute_here(scene_dir, plan: Plan, seed: int, video_path, max_wall_s: float, sac_steps: int,
                  retries: int = 1, reward_mode: str = "spec", final_graph_path=None, n_envs: int = 1,
                  recheck_fixes: int = 0) -> SkillResult:
    from anomalygen.control.driver import Driver
    from anomalygen.rng import item_rng
    from anomalygen.scene.graph import load_scene, scene_graph

    t0 = time.perf_counter()
    from anomalygen.perception import perceived_spec

    model, data, spec = load_scene(scene_dir)
    spec = perceived_spec(spec)  # the robot acts on what it perceives: no bindings, no roles
    timings = {"load_s": round(time.perf_counter() - t0, 3)}
    rec = None
    if video_path is not None:
        from anomalygen.control.video import VideoRecorder

        rec = VideoRecorder(model)
    drv = Driver(model, data, spec, rng=item_rng(seed, plan.task_id),
                 on_step=(lambda d: rec.capture(d.data)) if rec else None)
    before = scene_graph(model, data, spec) if recheck_fixes else None

    def run_steps(steps, plan: Plan) -> list[SubTaskResult]:
        results: list[SubTaskResult] = []
        for st in steps:
            ts = time.perf_counter()
            if st.method == SkillMethod.CEM:
                results.append(SubTaskResult(id=st.id, method=st.method, success=False, detail=(
                    "not executed: CEM plans the motion of a legged robot (rl/cem.py, the Gymnasium Ant); "
                    "household scenes carry the wheeled arm")))
                continue
            if time.perf_counter() - t0 > max_wall_s:
                results.append(SubTaskResult(id=st.id, method=st.method, success=False, detail="not executed: time budget spent"))
                continue
            s0 = drv.steps
            details: list[str] = []
            for attempt in range(1, 2 + (retries if st.method == SkillMethod.PRIMITIVE else 0)):
                if st.method == SkillMethod.SAC:
                    from anomalygen.rl.sac_subtask import run_sac_subtask

                    res = run_sac_subtask(drv, st, plan, steps=sac_steps, seed=seed, reward_mode=reward_mode,
                                          n_envs=n_envs)
                    drv.settle(10)
                    held = res.success and all(p.holds for p in _evaluate(st.success.predicates, model, data, spec,
                                                                          plan.bindings))
                    if not held and st.primitive and not res.detail.startswith("not executed: sac_steps is 0"):
                        # the learned policy failed, could not start, or its result did not last: the
                        # primitive behind the step gets its turn, and the result says both what SAC
                        # did and that it fell back
                        if res.success:
                            res.detail += "; its check failed afterwards"
                        prim = run_subtask(drv, st, plan)
                        res = PrimitiveResult(prim.success, res.steps + prim.steps,
                                             f"SAC failed ({res.detail}); fell back to the {st.primitive} primitive: {prim.detail}")
                else:
                    res = run_subtask(drv, st, plan)
                drv.settle(10)
                ok = res.success
                detail = res.detail
                if st.success.predicates:
                    preds = _evaluate(st.success.predicates, model, data, spec, plan.bindings)
                    ok = all(p.holds for p in preds)
                    detail += "; " + "; ".join(f"{p.call.name}: {'yes' if p.holds else 'no'}" for p in preds)
                details.append(detail if attempt == 1 else f"attempt {attempt}: {detail}")
                if ok or time.perf_counter() - t0 > max_wall_s:
                    break
            results.append(SubTaskResult(id=st.id, method=st.method, success=ok, steps=drv.steps - s0,
                                         wall_s=round(time.perf_counter() - ts, 3), detail=" | ".join(details),
                                         attempts=attempt))
        return results

    results = run_steps(plan.subtasks, plan)
    if before is not None and plan.subtasks:
        drv.settle(25)
        results += _look_again(drv, before, plan, recheck_fixes, run_steps)

    drv.settle(25)
    final = _evaluate(plan.success.predicates, model, data, spec, plan.bindings)
    if final_graph_path is not None:
        from anomalygen.runfolder import write_model

        write_model(Path(final_graph_path), scene_graph(model, data, spec))
    timings["execute_s"] = round(time.perf_counter() - t0 - timings["load_s"], 3)
    timings["control_steps"] = float(drv.steps)
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
