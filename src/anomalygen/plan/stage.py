"""Stage 4a: one ``plans/<task_id>.json`` per task, from ground truth or from the detection.

With ``plan_source = ground_truth`` the hazard class and role bindings come from the task and its
built scene; with ``detected`` the top hypothesis names the hazard class and the object at fault
(bound to ``$hazard``), so a wrong detection gives a wrong plan, as it should.

The learn engine picks the planner: ``knowledge`` turns the class's recipe into sub-tasks
(``planner.plan_from_kb``); ``llm`` asks the configured LLM for the decomposition
(``plan_llm.plan_from_llm``), validated against the built scene, and counts its tokens in the manifest.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from anomalygen.errors import ItemFailed, UserError
from anomalygen.runfolder import RunFolder, read_jsonl, try_read_model, write_model
from anomalygen.runner import StageContext, StageSummary, run_items
from anomalygen.schema import Detection, Plan, SceneSpec, TaskProposal

if TYPE_CHECKING:
    from anomalygen.config import Settings

STAGE = "plan"


def plan_item(task_id: str, payload: dict, ctx: StageContext) -> str:
    from anomalygen.plan.planner import plan_from_kb

    run, settings = ctx.run, ctx.settings
    spec = try_read_model(run.scene_dir(task_id) / "scene.json", SceneSpec)
    bindings = dict(spec.bindings) if spec is not None else {}
    hazard_class = payload["hazard_class"]
    source = settings.learn.plan_source
    hypothesis = None
    if source == "detected":
        det = payload.get("detection")
        if det is None or not det["hypotheses"]:
            raise ItemFailed("no detection for this task")
        top = min(det["hypotheses"], key=lambda h: h["rank"])
        if not top.get("hazard_class"):
            raise ItemFailed("top hypothesis names no hazard class")
        hazard_class = top["hazard_class"]
        bindings["$hazard"] = top["target_object"]
        hypothesis = top
    if settings.engine_for("learn").value == "llm":
        plan = _plan_with_llm(task_id, payload, ctx, hazard_class, bindings, spec, hypothesis)
    else:
        plan = plan_from_kb(task_id, hazard_class, bindings, spec=spec, source=source,
                            sac_actions=settings.learn.sac_actions)
    write_model(run.plan_path(task_id), plan)
    return str(run.plan_path(task_id))


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
    if hypothesis is not None:  # the task's own words would leak the ground truth into a detected plan
        hazard = hazard_text_from_hypothesis(hypothesis)
    else:
        hazard = hazard_text_from_task(TaskProposal.model_validate(payload["task"])) if payload.get("task") else ""
    client = shared_client(settings.llm)
    client.reset_usage()  # this item's requests only (the client is shared per process)
    try:
        return plan_from_llm(task_id, hazard_class, bindings, spec=spec, client=client, hazard=hazard,
                             source=settings.learn.plan_source, seed=settings.seed)
    finally:
        usage = client.reset_usage()
        if usage.requests or usage.cache_hits:
            record_usage(ctx.run, usage)


def run_stage(run: RunFolder, settings: Settings, *, force: bool = False, only: list[str] | None = None) -> StageSummary:
    engine = settings.engine_for("learn")
    if engine.value == "llm" and not settings.llm.configured:
        raise UserError("the llm learn engine needs an LLM: pass --backend openai|anthropic|llamacpp "
                        "(or use --engine knowledge)")
    tasks = run.load_tasks()
    detections = {}
    if settings.learn.plan_source == "detected" and run.detections_path.is_file():
        detections = {d.task_id: d for d in read_jsonl(run.detections_path, Detection, strict=False)}
    items = []
    for t in tasks:
        if only and t.id not in only:
            continue
        det = detections.get(t.id)
        items.append((t.id, {"hazard_class": t.hazard_class, "detection": det.model_dump(mode="json") if det else None,
                             "task": t.model_dump(mode="json")}))

    def done(task_id: str) -> bool:
        plan = try_read_model(run.plan_path(task_id), Plan)
        return plan is not None and plan.source == settings.learn.plan_source and plan.engine == engine

    return run_items(run, STAGE, items, plan_item, settings=settings, is_done=done, force=force, workers=1)
