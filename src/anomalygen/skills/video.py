"""Small MP4 recordings of skill executions (front camera, 320x240, 15 fps).

Frames are rendered every few control steps and encoded with imageio-ffmpeg into a temp file next
to the destination, then renamed, so a reader (the report) never sees half a video.

The frames are drawn without shadows, reflections or multisampling. With software OpenGL (CI and
the demo have no GPU) those three made a frame cost about 78 ms instead of 9 ms in a room with walls,
and the video was 95 % of a plan's execution time (profiled on the demo's baby-gate task: 614 frames,
38 s of 40 s). A video is a record of what the arm did, not an input to anything, so it gives them up;
the scene renders that detection reads keep the full quality.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np


class VideoRecorder:
    """Collects frames from a MuJoCo camera; ``every`` control steps per frame keeps files small."""

    def __init__(self, model, *, camera: str = "front", width: int = 320, height: int = 240, every: int = 3,
                 max_frames: int = 900):
        import mujoco

        self.model, self.camera, self.every, self.max_frames = model, camera, max(1, int(every)), int(max_frames)
        samples = model.vis.quality.offsamples
        model.vis.quality.offsamples = 0  # read once, when the offscreen buffer is made
        try:
            self._renderer = mujoco.Renderer(model, height=height, width=width)
        finally:
            model.vis.quality.offsamples = samples
        flags = self._renderer.scene.flags  # kept by every update_scene
        flags[mujoco.mjtRndFlag.mjRND_SHADOW] = flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = 0
        self.frames: list[np.ndarray] = []
        self._n = 0

    def capture(self, data, *, force: bool = False) -> None:
        self._n += 1
        if not force and (self._n % self.every or len(self.frames) >= self.max_frames):
            return
        self._renderer.update_scene(data, camera=self.camera)
        self.frames.append(self._renderer.render().copy())

    def save(self, path: Path, fps: int = 15) -> Path | None:
        """Encode to ``path`` atomically; returns None when no frame was captured."""
        import imageio.v2 as imageio

        if not self.frames:
            return None
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.stem}.{os.getpid()}.tmp.mp4")
        with imageio.get_writer(tmp, fps=fps, codec="libx264", quality=6, macro_block_size=8,
                                ffmpeg_log_level="error") as w:
            for f in self.frames:
                w.append_data(f)
        os.replace(tmp, path)
        return path

    def close(self) -> None:
        self._renderer.close()
