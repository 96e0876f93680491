"""Stage 3 entry point: detect the hazards in every built scene and collate the detections.

Per scene (one runner item): read ``scene_graph.json`` through ``anomalygen.world.perception`` (the only
input a detector sees; with ``detect.noise`` on, a noisy copy of it, ``detect/noise.py``), run the
configured detector and write ``detections/<task_id>.json`` (which records the noise it ran under). A detector failure (an LLM that never
produced a valid reply) is recorded in that scene's ``Detection.error`` and counts as a miss; it
never ends the batch. After the items: collate ``detections.jsonl`` atomically in task order and
print what was claimed.

Nothing here reads the task or the scene's truth: detections are scored against the truth on the
evaluate side (``anomalygen evaluate`` writes ``detections_summary.json``).
"""

from __future__ import annotations

from collections import Counter
from typing import TYPE_CHECKING, Any

from anomalygen.errors import ItemFailed, UserError
from anomalygen.runfolder import RunFolder, try_read_model, write_jsonl, write_model
from anomalygen.runner import StageContext, StageSummary, check_only, config_section, run_items
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
    """Detect on one scene graph (pure apart from LLM calls): what the item function writes. The
    task id only names the record; the detector is given the graph alone, through the configured
    perception noise (``detect.noise``; off: the graph itself), which the record keeps."""
    from anomalygen.detect.noise import detector_graph
    from anomalygen.llm import LLMItemError

    detector = detector or make_detector(settings)
    seen, noise = detector_graph(graph, settings)
    error = None
    try:
        hyps = detector.detect(seen, settings.detect.k)
    except LLMItemError as exc:
        hyps, error = [], str(exc)
    return Detection(task_id=task_id, scene_id=graph.scene_id, detector=_detector_name(detector, settings),
                     hypotheses=hyps, error=error, noise=noise)


def _item(task_id: str, payload: dict[str, Any], ctx: StageContext) -> dict[str, Any]:
    from anomalygen.world.perception import load_scene_graph

    run, settings = ctx.run, ctx.settings
    graph = load_scene_graph(run.scene_dir(task_id))
    if graph is None:
        raise ItemFailed(f"no valid scene_graph.json in {run.scene_dir(task_id)} (build the scene first)")
    detector = make_detector(settings)
    client = getattr(detector, "client", None)
    if client is not None:
        client.reset_usage()  # count this scene's requests only (the client is shared per process)
    det = detect_scene(task_id, graph, settings, detector=detector)
    write_model(detection_path(run, task_id), det)
    usage = client.reset_usage().model_dump() if client is not None else None
    return {"claims": len(det.hypotheses), "error": det.error, "fallback": getattr(detector, "fell_back", None),
            "usage": usage}


def _graph_path(run: RunFolder, task_id: str):
    from anomalygen.scene_files import SCENE_GRAPH

    return run.scene_dir(task_id) / SCENE_GRAPH


def _is_done_for(run: RunFolder, settings: Settings):
    def is_done(task_id: str) -> bool:
        det = try_read_model(detection_path(run, task_id), Detection)
        return (det is not None and det.error is None and det.detector == settings.detect.detector
                and len(det.hypotheses) <= settings.detect.k)
    return is_done


def reads(settings: Settings) -> dict:
    """What a detect item reads of the settings (its fingerprint's config part): all of ``[detect]``;
    the master seed when ``detect.noise`` is on (the noise is drawn from it); the LLM's identity for the
    llm and hybrid detectors (they ask it with a fixed seed of their own)."""
    return config_section(settings, "detect", seed=settings.detect.noise.enabled,
                          llm=settings.detect.detector != "rules")


def run_stage(run: RunFolder, settings: Settings, *, force: bool = False, only: list[str] | None = None) -> StageSummary:
    tasks = run.load_tasks()
    check_only(only, [t.id for t in tasks])
    make_detector(settings)  # fail fast (no LLM for llm/hybrid) before any item runs
    chosen = [t.id for t in tasks if not only or t.id in only]
    # A task whose scene was never built (or failed to build) is the build stage's failure, already
    # recorded there; evaluate lists it as missing instead of failing it a second time here.
    built = [tid for tid in chosen if _graph_path(run, tid).is_file()]
    if only and len(built) < len(chosen):
        missing = sorted(set(chosen) - set(built))
        raise UserError(f"no built scene for: {', '.join(missing)} (run 'anomalygen build' first)")
    summary = run_items(run, STAGE, [(tid, {}) for tid in built], _item, settings=settings,
                        is_done=_is_done_for(run, settings), force=force,
                        description=f"detect ({settings.detect.detector})",
                        inputs=lambda tid: [_graph_path(run, tid)],
                        config=reads(settings))
    _record_llm_usage(run, summary)

    detections = [d for t in tasks if (d := try_read_model(detection_path(run, t.id), Detection)) is not None]
    write_jsonl(run.detections_path, detections)
    fallbacks = sum(1 for r in summary.results.values() if isinstance(r, dict) and r.get("fallback"))
    if not settings.quiet:
        from rich.console import Console

        console = Console(stderr=True)
        claims = Counter(len(d.hypotheses) for d in detections)
        console.print(f"detections ({settings.detect.detector}): {len(detections)} scenes, "
                      f"{sum(n * c for n, c in claims.items())} claims, {claims.get(0, 0)} scenes with none, "
                      f"{sum(1 for d in detections if d.error)} failed; scored against the truth by "
                      "'anomalygen evaluate' (detections_summary.json)", highlight=False)
        if fallbacks:
            console.print(f"[yellow]{fallbacks} scene(s): LLM ranking failed, rule order kept[/yellow]")
    return summary


def _record_llm_usage(run: RunFolder, summary: StageSummary) -> None:
    from anomalygen.schema import LLMUsage

    total = LLMUsage()
    for r in summary.results.values():
        if isinstance(r, dict) and r.get("usage"):
            total.add(LLMUsage.model_validate(r["usage"]))
    if total.requests or total.cache_hits:
        from anomalygen.llm import record_usage

        record_usage(run, total)
