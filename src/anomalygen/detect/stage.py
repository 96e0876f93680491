"""Stage 3 entry point: detect the hazard in every built scene, judge it, collate, summarise.

Per scene (one runner item): read ``scene_graph.json`` through ``anomalygen.perception`` (the only
input a detector sees; with ``detect.noise`` on, a noisy copy of it, ``detect/noise.py``), run the
configured detector, then judge its hypotheses against the hidden task and write
``detections/<task_id>.json`` (which records the noise settings used). A detector failure (an LLM that never produced a valid reply) is
recorded in that scene's ``Detection.error`` and counts as a miss; it never ends the batch. After the
items: collate ``detections.jsonl`` atomically in task order, write ``detections_summary.json`` and
print the hit@k table.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from anomalygen.errors import ItemFailed, UserError
from anomalygen.runfolder import RunFolder, try_read_model, write_jsonl, write_model
from anomalygen.runner import StageContext, StageSummary, run_items
from anomalygen.schema import Detection, PerceptionNoise, SceneGraph, SceneSpec, TaskProposal

if TYPE_CHECKING:
    from anomalygen.config import Settings

STAGE = "detect"


def summary_path(run: RunFolder):
    return run.root / "detections_summary.json"


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


def make_judge(settings: Settings):
    from anomalygen.detect.judge import Judge

    client = None
    if settings.llm.configured and settings.detect.llm_judge:
        client = _client(settings.llm)
    # Rule and hybrid hypotheses name a knowledge-base class, so the exact comparison decides them.
    decisive = settings.detect.detector in ("rules", "hybrid")
    return Judge(threshold=settings.detect.judge_threshold, llm_client=client, structured_decisive=decisive)


def _detector_name(detector, settings: Settings) -> str:
    """A hybrid that fell back on the rule order produced a rule detection: say so per scene."""
    return "rules" if getattr(detector, "fell_back", None) else settings.detect.detector


def detect_scene(task: TaskProposal, graph: SceneGraph, spec: SceneSpec | None, settings: Settings, *, detector=None,
                 judge=None, hazard_free: bool = False, seen: SceneGraph | None = None,
                 noise: PerceptionNoise | None = None) -> Detection:
    """Detect and judge one scene (pure apart from LLM calls): what the item function writes.

    The detector sees the graph only (``seen``, the noisy copy, when perception noise is on; its
    record is ``noise``); the task, the spec, the perfect graph and ``hazard_free`` (the scene's
    truth.json lists no hazard) are for judging its answer afterwards."""
    from anomalygen.detect.judge import first_hit, miss_reason
    from anomalygen.detect.truth import ground_truth
    from anomalygen.llm import LLMItemError

    detector = detector or make_detector(settings)
    judge = judge or make_judge(settings)
    error = None
    try:
        hyps = detector.detect(graph if seen is None else seen, settings.detect.k)
    except LLMItemError as exc:
        hyps, error = [], str(exc)
    if hazard_free:  # nothing to find: there is no hit to rank, only claims that are false alarms
        return Detection(task_id=task.id, scene_id=graph.scene_id, detector=_detector_name(detector, settings),
                         hypotheses=hyps, hazard_free=True, error=error, noise=noise,
                         miss_reason=f"detector failed: {error}" if error else None)
    truth = ground_truth(task, spec, graph, hazard_variable=_hazard_variable(task.hazard_class))
    judgements = judge.judge(hyps, truth, graph)
    hit = first_hit(judgements)
    return Detection(
        task_id=task.id,
        scene_id=graph.scene_id,
        detector=_detector_name(detector, settings),
        hypotheses=hyps,
        judgements=judgements,
        hit_rank=hit,
        miss_reason=None if hit is not None else (f"detector failed: {error}" if error else miss_reason(hyps, judgements, truth)),
        error=error,
        noise=noise,
    )


def _hazard_variable(class_id: str) -> str | None:
    """The knowledge base's variable for the object at fault of a class (None for unknown classes)."""
    from anomalygen.knowledge import load_kb

    hc = load_kb().hazard_classes.get(class_id)
    return hc.hazard_variable if hc is not None else None


def _item(task_id: str, payload: dict[str, Any], ctx: StageContext) -> dict[str, Any]:
    from anomalygen.detect.noise import detector_graph
    from anomalygen.perception import load_scene_graph

    run, settings = ctx.run, ctx.settings
    scene_dir = run.scene_dir(task_id)
    graph = load_scene_graph(scene_dir)
    if graph is None:
        raise ItemFailed(f"no valid scene_graph.json in {scene_dir} (build the scene first)")
    spec = try_read_model(scene_dir / "scene.json", SceneSpec)
    task = TaskProposal.model_validate(payload["task"])
    detector = make_detector(settings)
    judge = make_judge(settings)
    client = getattr(detector, "client", None) or judge.llm
    if client is not None:
        client.reset_usage()  # count this scene's requests only (the client is shared per process)
    from anomalygen.scene.truth import load_manifest

    truth = load_manifest(scene_dir)  # judging only: the detector has already been given the graph alone
    seen, noise = detector_graph(graph, settings)
    det = detect_scene(task, graph, spec, settings, detector=detector, judge=judge,
                       hazard_free=truth is not None and not truth.hazards, seen=seen, noise=noise)
    write_model(detection_path(run, task_id), det)
    usage = client.reset_usage().model_dump() if client is not None else None
    return {
        "hit_rank": det.hit_rank,
        "error": det.error,
        "fallback": getattr(detector, "fell_back", None),
        "usage": usage,
    }


def _is_done_for(run: RunFolder, settings: Settings):
    def is_done(task_id: str) -> bool:
        det = try_read_model(detection_path(run, task_id), Detection)
        return (det is not None and det.error is None and det.detector == settings.detect.detector
                and len(det.hypotheses) <= settings.detect.k and _same_noise(det.noise, settings))
    return is_done


def _same_noise(record: PerceptionNoise | None, settings: Settings) -> bool:
    """Was a detection made under the configured perception noise (or none, both times)?"""
    cfg = settings.detect.noise
    if record is None or not cfg.enabled:
        return record is None and not cfg.enabled
    asked = (cfg.pose_jitter, cfg.miss_rate, cfg.small_size, cfg.confusion_rate, settings.seed)
    return (record.pose_jitter, record.miss_rate, record.small_size, record.confusion_rate, record.seed) == asked


def run_stage(run: RunFolder, settings: Settings, *, force: bool = False, only: list[str] | None = None) -> StageSummary:
    from anomalygen.detect.report import print_report, summarise

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
    items = [(t.id, {"task": t.model_dump(mode="json")}) for t in built]
    summary = run_items(run, STAGE, items, _item, settings=settings, is_done=_is_done_for(run, settings), force=force,
                        description=f"detect ({settings.detect.detector})")
    _record_llm_usage(run, summary)

    detections = [d for t in tasks if (d := try_read_model(detection_path(run, t.id), Detection)) is not None]
    write_jsonl(run.detections_path, detections)
    report = summarise(detections, tasks, settings.detect.k)
    report.scores = _scores_against_truth(run, tasks, detections, settings.detect.k)
    write_model(summary_path(run), report)
    fallbacks = sum(1 for r in summary.results.values() if isinstance(r, dict) and r.get("fallback"))
    if not settings.quiet:
        from rich.console import Console

        console = Console(stderr=True)
        print_report(report, console=console)
        if fallbacks:
            console.print(f"[yellow]{fallbacks} scene(s): LLM ranking failed, rule order kept[/yellow]")
    summary.results["report"] = report.model_dump(mode="json")
    return summary


def _scores_against_truth(run: RunFolder, tasks, detections, k: int):
    """Per-hazard scores against the scenes' truth.json, read here (after detection) by the scorer only."""
    from anomalygen.detect.score import score_detections
    from anomalygen.evaluate.run_metrics import load_manifests

    manifests = load_manifests(run, tasks)
    return score_detections(detections, manifests, k) if manifests else None


def _record_llm_usage(run: RunFolder, summary: StageSummary) -> None:
    from anomalygen.schema import LLMUsage

    total = LLMUsage()
    for r in summary.results.values():
        if isinstance(r, dict) and r.get("usage"):
            total.add(LLMUsage.model_validate(r["usage"]))
    if total.requests or total.cache_hits:
        from anomalygen.llm import record_usage

        record_usage(run, total)
