"""``anomalygen build``: every task in the run becomes ``scenes/<task_id>/`` (resumable, parallel).

A scene counts as done when its ``scene.json`` exists, validates as a SceneSpec and its validation
report is ok (scene.json is written last, so a crash mid-scene leaves it undone). The item function
is module-level so the process pool and Ray can pickle it. After the batch, a contact sheet of up to
10 random front renders goes to ``scenes/contact_sheet.png`` for a quick visual check.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from anomalygen.runfolder import RunFolder, atomic_write_bytes, try_read_model, write_model
from anomalygen.runner import StageContext, StageSummary, check_only, config_section, run_items
from anomalygen.scene_files import CONTACT_SHEET, LLM_LAYOUT, SCENE_SPEC
from anomalygen.schema import Engine, SceneSpec, TaskProposal

if TYPE_CHECKING:
    from anomalygen.config import Settings

STAGE = "build"
SHEET_N = 10


def scene_ok(scene_dir: Path) -> bool:
    spec = try_read_model(Path(scene_dir) / SCENE_SPEC, SceneSpec)
    return spec is not None and spec.validation is not None and spec.validation.ok


def build_item(item_id: str, payload: str, ctx: StageContext) -> str:
    """Build one task's scene; returns the scene id (ItemFailed propagates as the item's reason)."""
    from anomalygen.scene.build import build_scene
    from anomalygen.scene.mix import is_hazard_free

    task = TaskProposal.model_validate_json(payload)
    settings = ctx.settings
    out_dir = ctx.run.scene_dir(item_id)
    with _one_torch_thread():
        hints = None
        if settings.build.engine == Engine.LLM:  # explicit only: the offline engine stays the default
            from anomalygen.scene.llm_engine import plan_scene

            hints = plan_scene(task, settings)
        spec = build_scene(task, seed=settings.seed, settings=settings, out_dir=out_dir, hints=hints,
                           hazard_free=is_hazard_free(task.id, settings, source=task.source))
    if hints is not None:
        write_model(out_dir / LLM_LAYOUT, hints)  # what the LLM said, before the builder's corrections
    return spec.scene_id


class _one_torch_thread:
    """SBERT ranks a few short texts per scene; with two build workers on two cores, torch's own
    thread pool only thrashes (measured: seconds per scene under load). Restored afterwards, because
    with one worker the item runs inline in the caller's process."""

    def __enter__(self):
        import torch

        self.before = torch.get_num_threads()
        torch.set_num_threads(1)

    def __exit__(self, *exc):
        import torch

        torch.set_num_threads(self.before)


def reads(settings: Settings) -> dict:
    """What a build item reads of the settings (its fingerprint's config part): all of ``[build]`` and
    the master seed; the LLM's identity when it lays the scene out (``build.engine = llm``) or checks
    the render (a configured LLM with ``llm.vision``, ``scene/verify.py``; then ``llm.vision`` too).
    A configured LLM that does neither is not read: its settings redo no scene."""
    vlm = settings.llm.configured and settings.llm.vision
    return config_section(settings, "build", also={"llm": ("vision",)} if vlm else None,
                          llm=settings.build.engine == Engine.LLM or vlm)


def run_stage(
    run: RunFolder, settings: Settings, *, force: bool = False, only: list[str] | None = None
) -> StageSummary:
    tasks = run.load_tasks()
    check_only(only, [t.id for t in tasks])
    if only:
        wanted = set(only)
        tasks = [t for t in tasks if t.id in wanted]
    items = [(t.id, t.model_dump_json()) for t in tasks]
    summary = run_items(
        run,
        STAGE,
        items,
        build_item,
        settings=settings,
        is_done=lambda task_id: scene_ok(run.scene_dir(task_id)),
        force=force,
        description="build scenes",
        config=reads(settings),
    )
    try:
        write_contact_sheet(run, seed=settings.seed)
    except Exception:  # noqa: BLE001 - a missing preview must not fail the stage
        pass
    return summary


def write_contact_sheet(run: RunFolder, *, seed: int = 0, n: int = SHEET_N) -> Path | None:
    """Tile up to ``n`` randomly chosen front renders (with their task ids) into one PNG."""
    from PIL import Image, ImageDraw

    from anomalygen.rng import item_rng

    renders = sorted(p for p in run.scenes_dir.glob("*/render_front.png") if scene_ok(p.parent))
    if not renders:
        return None
    rng = item_rng(seed, "contact_sheet")
    pick = [renders[i] for i in sorted(rng.choice(len(renders), size=min(n, len(renders)), replace=False))]
    images = [Image.open(p).convert("RGB") for p in pick]
    w, h = images[0].size
    cols = min(5, len(images))
    rows = (len(images) + cols - 1) // cols
    sheet = Image.new("RGB", (cols * w, rows * (h + 16)), "white")
    draw = ImageDraw.Draw(sheet)
    for i, (img, path) in enumerate(zip(images, pick, strict=True)):
        x, y = (i % cols) * w, (i // cols) * (h + 16)
        sheet.paste(img.resize((w, h)), (x, y + 16))
        draw.text((x + 4, y + 2), path.parent.name, fill="black")
    import io

    buf = io.BytesIO()
    sheet.save(buf, format="PNG")
    out = run.scenes_dir / CONTACT_SHEET
    atomic_write_bytes(out, buf.getvalue())
    return out


def revalidate_run(run: RunFolder, settings: Settings | None = None) -> dict[str, str | None]:
    """Re-check every built scene from its files alone: load scene.xml at its settled keyframe,
    rebuild the scene graph and evaluate the hazard class's preconditions (and penetration) again.
    Returns task id -> None when valid, else the reason. Used by tests and the acceptance run."""
    from anomalygen.knowledge import load_kb
    from anomalygen.scene.validate import validate
    from anomalygen.world.graph import load_scene, scene_graph

    kb = load_kb()
    out: dict[str, str | None] = {}
    for task in run.load_tasks():
        folder = run.scene_dir(task.id)
        if not scene_ok(folder):
            continue
        model, data, spec = load_scene(folder)
        graph = scene_graph(model, data, spec)
        # a hazard-free scene (no bindings) has no class preconditions to hold, as when it was built
        hc = kb.hazard_classes.get(task.hazard_class) if spec.bindings else None
        report = validate(model, data, spec, graph, hc)
        out[task.id] = None if report.ok else report.reason
    return out
