"""Stage 4a: one ``plans/<task_id>.json`` per scene, from the detection (default) or from the oracle.

With ``plan.source = detected`` (the default) the robot plans from what it perceived: every
hypothesis worth acting on (a known class, score at least ``plan.min_score``, one per object, most
severe first, up to ``plan.max_fixes``) becomes a fix whose roles (container, support, ...) are
chosen from the perceived scene graph (``plan.bind``); the scene spec it reads has the answer key
removed (``anomalygen.world.perception``). A scene where nothing was detected gets an empty plan: acting
there would be an unnecessary intervention. A wrong detection gives a wrong plan, as it should.

With ``plan.source = ground_truth`` the task's class and the builder's bindings are used: the oracle
ablation, for comparison only.

The plan engine (``plan.engine``) picks the planner: ``knowledge`` turns the class's recipe into sub-tasks
(``planner.plan_from_kb``); ``llm`` asks the configured LLM for the decomposition
(``plan_llm.plan_from_llm``), validated against the built scene, and counts its tokens in the manifest.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from anomalygen.errors import ItemFailed, UserError
from anomalygen.runfolder import RunFolder, read_jsonl, try_read_model, write_model
from anomalygen.runner import StageContext, StageSummary, check_only, config_section, run_items
from anomalygen.scene_files import SCENE_GRAPH, SCENE_SPEC
from anomalygen.schema import Detection, Engine, Plan, SceneSpec, SuccessSpec, TaskProposal

if TYPE_CHECKING:
    from anomalygen.config import Settings

STAGE = "plan"


def plan_item(task_id: str, payload: dict, ctx: StageContext) -> str:
    run, settings = ctx.run, ctx.settings
    if settings.plan.source == "detected":
        plan = _plan_from_perception(task_id, payload, ctx)
    else:
        plan = _plan_from_oracle(task_id, payload, ctx)
    write_model(run.plan_path(task_id), plan)
    return str(run.plan_path(task_id))


def _plan_from_oracle(task_id: str, payload: dict, ctx: StageContext) -> Plan:
    """The oracle ablation: the task's class and the builder's bindings (the answer key)."""
    from anomalygen.plan.planner import plan_from_kb

    settings = ctx.settings
    spec = try_read_model(ctx.run.scene_dir(task_id) / SCENE_SPEC, SceneSpec)
    bindings = dict(spec.bindings) if spec is not None else {}
    hazard_class = payload["hazard_class"]
    if spec is not None and not spec.bindings:  # a hazard-free scene: the oracle knows there is nothing to fix
        return Plan(task_id=task_id, source="ground_truth", engine=settings.engine_for("plan"), subtasks=[],
                    success=SuccessSpec(predicates=[]), bindings={})
    if settings.engine_for("plan").value == "llm":
        return _plan_with_llm(task_id, payload, ctx, hazard_class, bindings, spec, None)
    return plan_from_kb(task_id, hazard_class, bindings, spec=spec, source="ground_truth",
                        sac_actions=settings.plan.sac_actions)


def _plan_from_perception(task_id: str, payload: dict, ctx: StageContext) -> Plan:
    """Fix what was detected, most severe first, with every role chosen from the perceived scene."""
    from anomalygen.knowledge import load_kb
    from anomalygen.plan.bind import bind_fix
    from anomalygen.plan.fixes import choose_fixes, fixes_to_make
    from anomalygen.plan.planner import merge_plans, plan_from_kb
    from anomalygen.world.perception import load_perceived_spec, load_scene_graph

    settings = ctx.settings
    det = payload.get("detection")
    if det is None:
        raise ItemFailed("no detection for this scene (run 'anomalygen detect' first)")
    spec = load_perceived_spec(ctx.run.scene_dir(task_id))
    graph = load_scene_graph(ctx.run.scene_dir(task_id))
    if spec is None or graph is None:
        raise ItemFailed(f"no built scene in {ctx.run.scene_dir(task_id)}")
    kb = load_kb()
    if settings.engine_for("plan").value == "llm":
        chosen = fixes_to_make(det["hypotheses"], kb, max_fixes=settings.plan.max_fixes,
                               min_score=settings.plan.min_score)
        if not chosen:
            return _nothing_to_fix(task_id, settings)
        top = chosen[0]
        bindings = bind_fix(kb.hazard_classes[top["hazard_class"]], top["target_object"], graph, kb)
        return _plan_with_llm(task_id, payload, ctx, top["hazard_class"], bindings, spec, top)
    fixes, dropped = choose_fixes(det["hypotheses"], graph, kb, max_fixes=settings.plan.max_fixes,
                                  min_score=settings.plan.min_score)
    if not fixes:  # nothing detected worth acting on: the right plan is to leave the scene alone
        return _nothing_to_fix(task_id, settings)
    plans = [plan_from_kb(task_id, f.hazard_class, f.bindings, spec=spec, source="detected",
                          sac_actions=settings.plan.sac_actions) for f in fixes]
    return merge_plans(plans).model_copy(update={"dropped": dropped})


def _nothing_to_fix(task_id: str, settings: Settings) -> Plan:
    return Plan(task_id=task_id, source="detected", engine=settings.engine_for("plan"), subtasks=[],
                success=SuccessSpec(predicates=[]), bindings={})


def _plan_with_llm(task_id: str, payload: dict, ctx: StageContext, hazard_class: str, bindings: dict[str, str],
                   spec: SceneSpec | None, hypothesis: dict | None) -> Plan:
    """The LLM engine for one item; its usage goes to the manifest whether or not the item succeeds."""
    from anomalygen.llm import record_usage, shared_client
    from anomalygen.plan.llm_prompt import hazard_text_from_hypothesis, hazard_text_from_task
    from anomalygen.plan.plan_llm import plan_from_llm

    settings = ctx.settings
    if spec is None:
        raise ItemFailed(f"no valid scene.json in {ctx.run.scene_dir(task_id)}; the LLM planner plans against "
                         "the built scene (run 'anomalygen build' first)")
    if hypothesis is not None:  # the task's own words would leak the answer key into a detected plan
        hazard = hazard_text_from_hypothesis(hypothesis)
    else:
        hazard = hazard_text_from_task(TaskProposal.model_validate(payload["task"])) if payload.get("task") else ""
    client = shared_client(settings.llm)
    client.reset_usage()  # this item's requests only (the client is shared per process)
    try:
        return plan_from_llm(task_id, hazard_class, bindings, spec=spec, client=client, hazard=hazard,
                             source="detected" if hypothesis is not None else "ground_truth", seed=settings.seed)
    finally:
        usage = client.reset_usage()
        if usage.requests or usage.cache_hits:
            record_usage(ctx.run, usage)


def reads(settings: Settings) -> dict:
    """What a plan item reads of the settings (its fingerprint's config part): all of ``[plan]``; with
    the llm engine (``plan.engine``, or a configured LLM while it is unset), the model that answers and
    the seed it is asked with. Not ``[learn]``: the plan stage reads none of it."""
    llm = settings.engine_for("plan") == Engine.LLM
    return config_section(settings, "plan", seed=llm, llm=llm)


def run_stage(run: RunFolder, settings: Settings, *, force: bool = False, only: list[str] | None = None) -> StageSummary:
    engine = settings.engine_for("plan")
    if engine.value == "llm" and not settings.llm.configured:
        raise UserError("the llm plan engine needs an LLM: pass --backend openai|anthropic|llamacpp "
                        "(or use --engine knowledge)")
    tasks = run.load_tasks()
    check_only(only, [t.id for t in tasks])
    detections = {}
    if settings.plan.source == "detected" and run.detections_path.is_file():
        detections = {d.task_id: d for d in read_jsonl(run.detections_path, Detection, strict=False)}
    items = []
    for t in tasks:
        if only and t.id not in only:
            continue
        det = detections.get(t.id)
        if settings.plan.source == "detected":  # the robot's side: its detection, never the task
            # what the detector claimed, never how the referee judged it
            items.append((t.id, {"detection": det.model_dump(mode="json", include={"task_id", "hypotheses"})
                                 if det else None}))
        else:
            items.append((t.id, {"hazard_class": t.hazard_class, "task": t.model_dump(mode="json")}))

    def done(task_id: str) -> bool:
        plan = try_read_model(run.plan_path(task_id), Plan)
        return plan is not None and plan.source == settings.plan.source and plan.engine == engine

    return run_items(run, STAGE, items, plan_item, settings=settings, is_done=done, force=force, workers=1,
                     inputs=lambda tid: [run.scene_dir(tid) / SCENE_SPEC, run.scene_dir(tid) / SCENE_GRAPH],
                     config=reads(settings))
