"""Stage 4a: one ``plans/<task_id>.json`` per task, from ground truth or from the detection.

With ``plan_source = ground_truth`` the hazard class and role bindings come from the task and its
built scene; with ``detected`` the top hypothesis names the hazard class and the object at fault
(bound to ``$hazard``), so a wrong detection gives a wrong plan, as it should.
"""

from __future__ import annotations

from anomalygen.errors import ItemFailed
from anomalygen.runfolder import RunFolder, read_jsonl, try_read_model, write_model
from anomalygen.runner import StageContext, StageSummary, run_items
from anomalygen.schema import Detection, Plan, SceneSpec

STAGE = "plan"


def plan_item(task_id: str, payload: dict, ctx: StageContext) -> str:
    from anomalygen.learn.planner import plan_from_kb

    run, settings = ctx.run, ctx.settings
    spec = try_read_model(run.scene_dir(task_id) / "scene.json", SceneSpec)
    bindings = dict(spec.bindings) if spec is not None else {}
    hazard_class = payload["hazard_class"]
    source = settings.learn.plan_source
    if source == "detected":
        det = payload.get("detection")
        if det is None or not det["hypotheses"]:
            raise ItemFailed("no detection for this task")
        top = min(det["hypotheses"], key=lambda h: h["rank"])
        if not top.get("hazard_class"):
            raise ItemFailed("top hypothesis names no hazard class")
        hazard_class = top["hazard_class"]
        bindings["$hazard"] = top["target_object"]
    if settings.engine_for("learn").value == "llm":
        raise ItemFailed("the LLM planning engine is not implemented yet; use --engine knowledge")
    plan = plan_from_kb(task_id, hazard_class, bindings, spec=spec, source=source)
    write_model(run.plan_path(task_id), plan)
    return str(run.plan_path(task_id))


def run_stage(run: RunFolder, settings, *, force: bool = False, only: list[str] | None = None) -> StageSummary:
    tasks = run.load_tasks()
    detections = {}
    if settings.learn.plan_source == "detected" and run.detections_path.is_file():
        detections = {d.task_id: d for d in read_jsonl(run.detections_path, Detection, strict=False)}
    items = []
    for t in tasks:
        if only and t.id not in only:
            continue
        det = detections.get(t.id)
        items.append((t.id, {"hazard_class": t.hazard_class, "detection": det.model_dump(mode="json") if det else None}))

    def done(task_id: str) -> bool:
        plan = try_read_model(run.plan_path(task_id), Plan)
        return plan is not None and plan.source == settings.learn.plan_source

    return run_items(run, STAGE, items, plan_item, settings=settings, is_done=done, force=force, workers=1)
