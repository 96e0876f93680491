"""Stage 3 entry point: detect the hazard in every built scene and collate the detections.

Per scene (one runner item): read ``scene_graph.json`` (the only input a detector sees), run the
configured detector and write ``detections/<task_id>.json``. A detector failure (an LLM that never
produced a valid reply) is recorded in that scene's ``Detection.error`` and counts as a miss; it never
ends the batch. After the items: collate ``detections.jsonl`` atomically in task order and print one
line of what was claimed. Judging the claims against the hidden task and truth.json (hit@k, recall,
precision, ``detections_summary.json``) happens on the evaluate side, after the robot
(``anomalygen evaluate``, ``evaluate/judged_detections.py``).
"""

from __future__ import annotations

from collections import Counter
from typing import TYPE_CHECKING, Any

from anomalygen.errors import ItemFailed, UserError
from anomalygen.runfolder import RunFolder, try_read_model, write_jsonl, write_model
from anomalygen.runner import StageContext, StageSummary, run_items
from anomalygen.schema import Detection, SceneGraph

if TYPE_CHECKING:
    from anomalygen.config import Settings

STAGE = "detect"


def detection_path(run: RunFolder, task_id: str):
    return run.detections_dir / f"{task_id}.json"


def _client(llm):
    """One LLM client per process and configuration (its cache and HTTP pool are reused across scenes)."""
    from anomalygen.llm import shared_client

    return shared_client(llm)


def make_detector(settings: Settings):
    """The configured detector; 'llm' and 'hybrid' need an LLM and say so clearly when there is none."""
    from anomalygen.detect.rules import RuleDetector

    name = settings.detect.detector
    if name == "rules":
        return RuleDetector()
    if not settings.llm.configured:
        raise UserError(f"detector '{name}' needs an LLM: pass --backend openai|anthropic|llamacpp (or use --detector rules)")
    client = _client(settings.llm)
    if name == "llm":
        from anomalygen.detect.llm_detector import LLMDetector

        return LLMDetector(client)
    from anomalygen.detect.hybrid import HybridDetector

    return HybridDetector(client)


def _detector_name(detector, settings: Settings) -> str:
    """A hybrid that fell back on the rule order produced a rule detection: say so per scene."""
    return "rules" if getattr(detector, "fell_back", None) else settings.detect.detector


def detect_scene(task_id: str, graph: SceneGraph, settings: Settings, *, detector=None) -> Detection:
    """Detect on one scene graph (pure apart from LLM calls): what the item function writes.

    The detector sees the graph only; how its claims fare against the answer key is the referee's
    business, afterwards (``anomalygen evaluate``)."""
    from anomalygen.llm import LLMItemError

    detector = detector or make_detector(settings)
    error = None
    try:
        hyps = detector.detect(graph, settings.detect.k)
    except LLMItemError as exc:
        hyps, error = [], str(exc)
    return Detection(task_id=task_id, scene_id=graph.scene_id, detector=_detector_name(detector, settings),
                     hypotheses=hyps, error=error)


def _item(task_id: str, payload: dict[str, Any], ctx: StageContext) -> dict[str, Any]:
    run, settings = ctx.run, ctx.settings
    scene_dir = run.scene_dir(task_id)
    graph = try_read_model(scene_dir / "scene_graph.json", SceneGraph)
    if graph is None:
        raise ItemFailed(f"no valid scene_graph.json in {scene_dir} (build the scene first)")
    detector = make_detector(settings)
    client = getattr(detector, "client", None)
    if client is not None:
        client.reset_usage()  # count this scene's requests only (the client is shared per process)
    det = detect_scene(task_id, graph, settings, detector=detector)
    write_model(detection_path(run, task_id), det)
    usage = client.reset_usage().model_dump() if client is not None else None
    return {"error": det.error, "fallback": getattr(detector, "fell_back", None), "usage": usage}


def _is_done_for(run: RunFolder, settings: Settings):
    def is_done(task_id: str) -> bool:
        det = try_read_model(detection_path(run, task_id), Detection)
        return (det is not None and det.error is None and det.detector == settings.detect.detector
                and len(det.hypotheses) <= settings.detect.k)
    return is_done


def run_stage(run: RunFolder, settings: Settings, *, force: bool = False, only: list[str] | None = None) -> StageSummary:
    tasks = run.load_tasks()
    if only:
        unknown = sorted(set(only) - {t.id for t in tasks})
        if unknown:
            raise UserError(f"unknown task id(s): {', '.join(unknown)}")
    make_detector(settings)  # fail fast (no LLM for llm/hybrid) before any item runs
    chosen = [t for t in tasks if not only or t.id in only]
    # A task whose scene was never built (or failed to build) is the build stage's failure, already
    # recorded there; detection lists it in the report instead of failing it a second time.
    built = [t for t in chosen if (run.scene_dir(t.id) / "scene_graph.json").is_file()]
    if only and len(built) < len(chosen):
        missing = sorted({t.id for t in chosen} - {t.id for t in built})
        raise UserError(f"no built scene for: {', '.join(missing)} (run 'anomalygen build' first)")
    items = [(t.id, {}) for t in built]  # the detector gets the scene graph, never the task
    summary = run_items(run, STAGE, items, _item, settings=settings, is_done=_is_done_for(run, settings), force=force,
                        description=f"detect ({settings.detect.detector})")
    record_llm_usage(run, summary)

    detections = [d for t in tasks if (d := try_read_model(detection_path(run, t.id), Detection)) is not None]
    write_jsonl(run.detections_path, detections)
    fallbacks = sum(1 for r in summary.results.values() if isinstance(r, dict) and r.get("fallback"))
    if not settings.quiet:
        from rich.console import Console

        console = Console(stderr=True)
        console.print(claims_line(detections, settings.detect.detector), highlight=False)
        if fallbacks:
            console.print(f"[yellow]{fallbacks} scene(s): LLM ranking failed, rule order kept[/yellow]")
    return summary


def claims_line(detections: list[Detection], detector: str) -> str:
    """What the detector claimed, in one line (how the claims fare is for ``anomalygen evaluate`` to say)."""
    top = Counter(d.hypotheses[0].hazard_class or "free text" for d in detections if d.hypotheses)
    failed = sum(1 for d in detections if d.error)
    quiet = sum(1 for d in detections if not d.hypotheses and not d.error)
    common = ", ".join(f"{c} x{n}" for c, n in top.most_common(5))
    return (f"detect ({detector}): {len(detections)} scenes, {sum(len(d.hypotheses) for d in detections)} "
            f"hypotheses, {quiet} with none, {failed} failed; most common top-1 class: {common or 'none'}")


def record_llm_usage(run: RunFolder, summary: StageSummary) -> None:
    from anomalygen.schema import LLMUsage

    total = LLMUsage()
    for r in summary.results.values():
        if isinstance(r, dict) and r.get("usage"):
            total.add(LLMUsage.model_validate(r["usage"]))
    if total.requests or total.cache_hits:
        from anomalygen.llm import record_usage

        record_usage(run, total)
