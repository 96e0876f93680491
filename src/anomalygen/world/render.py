"""Offscreen rendering with one GL context per process.

``mujoco.Renderer`` creates a fresh GL context each time (~0.3-0.4 s with software EGL), which alone
would eat the scene builder's whole per-scene budget. Building many scenes in one worker, we keep a
single context and only upload each model's meshes and textures (``MjrContext``) once per model.
"""

from __future__ import annotations

import io
import os
import threading
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    import mujoco

_LOCK = threading.RLock()
_GL: dict[str, object] = {}


def _gl_context(width: int, height: int):

    os.environ.setdefault("MUJOCO_GL", "egl")
    ctx = _GL.get("ctx")
    if ctx is None or _GL["size"][0] < width or _GL["size"][1] < height:
        if ctx is not None:
            ctx.free()
        ctx = _context_class()(max(width, 640), max(height, 480))
        _GL["ctx"], _GL["size"] = ctx, (max(width, 640), max(height, 480))
    ctx.make_current()
    return ctx


def _context_class():
    """EGL when headless, even if mujoco was imported before MUJOCO_GL was set (it then picks GLFW)."""
    import mujoco

    if not os.environ.get("DISPLAY"):
        os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
        try:
            from mujoco.egl import GLContext

            return GLContext
        except Exception:  # noqa: BLE001 - fall back to whatever mujoco chose
            pass
    return mujoco.GLContext


class SceneRenderer:
    """Render named cameras of one model; call :meth:`close` (or use as a context manager)."""

    def __init__(self, model: mujoco.MjModel, width: int, height: int):
        import mujoco

        self.model, self.width, self.height = model, width, height
        self.con = None
        with _LOCK:
            _gl_context(width, height)
            if model.vis.global_.offwidth < width or model.vis.global_.offheight < height:
                model.vis.global_.offwidth = max(width, model.vis.global_.offwidth)
                model.vis.global_.offheight = max(height, model.vis.global_.offheight)
            self.con = mujoco.MjrContext(model, mujoco.mjtFontScale.mjFONTSCALE_100)
        self.scene = mujoco.MjvScene(model, maxgeom=4000)
        self.option = mujoco.MjvOption()
        self.camera = mujoco.MjvCamera()
        self.viewport = mujoco.MjrRect(0, 0, width, height)

    def render(self, data: mujoco.MjData, camera: str | int) -> np.ndarray:
        """RGB uint8 image (height, width, 3) from a named fixed camera."""
        import mujoco

        cam_id = (
            camera
            if isinstance(camera, int)
            else mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_CAMERA, camera)
        )
        if cam_id < 0:
            raise KeyError(f"no camera {camera!r}")
        self.camera.type = mujoco.mjtCamera.mjCAMERA_FIXED
        self.camera.fixedcamid = cam_id
        rgb = np.empty((self.height, self.width, 3), dtype=np.uint8)
        with _LOCK:  # one GL context per process: render calls of different models take turns
            _gl_context(self.width, self.height)
            mujoco.mjr_setBuffer(mujoco.mjtFramebuffer.mjFB_OFFSCREEN, self.con)
            mujoco.mjv_updateScene(
                self.model, data, self.option, None, self.camera, mujoco.mjtCatBit.mjCAT_ALL, self.scene
            )
            mujoco.mjr_render(self.viewport, self.scene, self.con)
            mujoco.mjr_readPixels(rgb, None, self.viewport, self.con)
        return np.flipud(rgb).copy()

    def segment(self, data: mujoco.MjData, camera: str | int, *, hide_group: int | None = None) -> np.ndarray:
        """Geom id per pixel (height, width; -1 where no geom is seen) from a named fixed camera;
        ``hide_group``: geoms of that group are left out."""
        import mujoco

        flags = (mujoco.mjtRndFlag.mjRND_SEGMENT, mujoco.mjtRndFlag.mjRND_IDCOLOR)
        groups = self.option.geomgroup.copy()
        for f in flags:
            self.scene.flags[f] = 1
        if hide_group is not None:
            self.option.geomgroup[hide_group] = 0
        try:
            rgb = self.render(data, camera).astype(np.int64)
        finally:
            for f in flags:
                self.scene.flags[f] = 0
            self.option.geomgroup[:] = groups
        seg = rgb[..., 0] + (rgb[..., 1] << 8) + (rgb[..., 2] << 16) - 1  # index into the scene's geoms
        lookup = np.full(self.scene.ngeom + 1, -1, dtype=np.int64)
        for i in range(self.scene.ngeom):
            g = self.scene.geoms[i]
            if g.objtype == mujoco.mjtObj.mjOBJ_GEOM:
                lookup[i] = g.objid
        return lookup[np.clip(seg, -1, self.scene.ngeom - 1)]

    def close(self) -> None:
        if self.con is not None:
            with _LOCK:
                _gl_context(self.width, self.height)
                self.con.free()
            self.con = None

    def __enter__(self) -> SceneRenderer:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self):  # pragma: no cover - best effort
        try:
            self.close()
        except Exception:  # noqa: BLE001
            pass


def png_bytes(rgb: np.ndarray) -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(rgb).save(buf, format="PNG", optimize=False, compress_level=3)
    return buf.getvalue()
