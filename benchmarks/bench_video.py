"""Cost of one episode-video frame, as the recorder draws it and at full render quality; prints JSON.

The recorder (``skills/video.py``) draws frames without shadows, reflections or multisampling, because
under software OpenGL those made the video most of a plan's execution time. This measures both on the
front camera of built scenes: a run folder's ``scenes/`` (e.g. ``runs/demo`` after ``make demo``), or
without ``--run`` the first ``--scenes`` knowledge tasks of seed 19 (the demo's), built in a temporary folder.

Usage: ``python benchmarks/bench_video.py [--run RUN_FOLDER] [--scenes N] [--frames N]``
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "egl")


def ms_per_frame(model, data, render, frames: int) -> float:
    render.update_scene(data, camera="front")
    render.render()  # warm-up
    t0 = time.perf_counter()
    for _ in range(frames):
        render.update_scene(data, camera="front")
        render.render()
    return (time.perf_counter() - t0) / frames * 1000


def main() -> None:
    import mujoco

    from anomalygen.skills.video import VideoRecorder
    from anomalygen.world.perception import load_perceived_scene

    ap = argparse.ArgumentParser()
    ap.add_argument("--run", type=Path, default=None)
    ap.add_argument("--scenes", type=int, default=5)
    ap.add_argument("--frames", type=int, default=30)
    a = ap.parse_args()
    if a.run is None:
        a.run = Path(tempfile.mkdtemp(prefix="bench_video_")) / "run"
        exe = str(Path(sys.executable).with_name("anomalygen"))
        for args in (["brainstorm", "--engine", "knowledge", "--seed", "19", "--n", str(a.scenes)], ["build"]):
            subprocess.run([exe, *args, "--out" if args[0] == "brainstorm" else "--run", str(a.run), "--quiet"], check=True)
    folders = sorted(p for p in (a.run / "scenes").iterdir() if (p / "scene.xml").exists())[: a.scenes]
    plain, full = [], []
    for folder in folders:
        model, data, _ = load_perceived_scene(folder)
        mujoco.mj_forward(model, data)
        rec = VideoRecorder(model)
        plain.append(ms_per_frame(model, data, rec._renderer, a.frames))
        rec.close()
        quality = mujoco.Renderer(model, height=240, width=320)
        full.append(ms_per_frame(model, data, quality, a.frames))
        quality.close()
    print(json.dumps({"name": "video", "scenes": len(folders), "frames_each": a.frames,
                      "recorder_ms_per_frame": round(statistics.median(plain), 1),
                      "full_quality_ms_per_frame": round(statistics.median(full), 1)}))


if __name__ == "__main__":
    main()
