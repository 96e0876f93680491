"""Thumbnails and the gallery contact sheet (offscreen MuJoCo, ``MUJOCO_GL=egl``).

A free camera (``MjvCamera``) aimed at the asset's bounding box avoids the fixed-camera trap (a camera
declared without xyaxes/targetbody looks straight down -z and misses the model).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from anomalygen.assets.model import Asset


def showcase_spec(asset: Asset, *, free: bool = False, lift: float = 0.0):
    """A scene with a floor, lights and the asset at the origin (optionally on a free joint)."""
    import mujoco

    from anomalygen.assets.finalize import new_spec

    spec = new_spec()
    spec.option.timestep = 0.002
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    size = max(asset.size, 0.05)
    spec.worldbody.add_geom(
        name="floor",
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[size * 4, size * 4, 0.1],
        rgba=[0.82, 0.8, 0.76, 1],
    )
    spec.worldbody.add_light(pos=[size, -2 * size, 3 * size], dir=[-0.3, 0.6, -1], diffuse=[0.7, 0.7, 0.7])
    spec.worldbody.add_light(
        pos=[-2 * size, -size, 2 * size], dir=[0.6, 0.3, -0.6], diffuse=[0.35, 0.35, 0.35]
    )
    spec.add_texture(
        name="sky",
        type=mujoco.mjtTexture.mjTEXTURE_SKYBOX,
        builtin=mujoco.mjtBuiltin.mjBUILTIN_GRADIENT,
        rgb1=[0.93, 0.95, 0.98],
        rgb2=[0.75, 0.8, 0.88],
        width=64,
        height=64,
    )
    spec.visual.headlight.ambient = [0.35, 0.35, 0.35]
    spec.visual.headlight.diffuse = [0.3, 0.3, 0.3]
    holder = spec.worldbody.add_body(name="holder", pos=[0, 0, (0.0005 * size if free else 0.0) + lift])
    body = asset.attach(holder, "a_")
    if free:
        holder.add_freejoint(name="free")
    return spec, body


def render_asset(
    asset: Asset,
    *,
    width: int = 320,
    height: int = 240,
    azimuth: float = 120.0,
    elevation: float = -24.0,
    open_fraction: float = 0.0,
    model=None,
    data=None,
) -> np.ndarray:
    """An RGB thumbnail (H, W, 3 uint8), viewed from the front (-y) side.

    ``open_fraction`` poses doors, drawers and lids part-way open so a cabinet reads as a cabinet.
    """
    os.environ.setdefault("MUJOCO_GL", "egl")
    import mujoco

    if model is None:
        spec, _ = showcase_spec(asset)
        model = spec.compile()
        data = mujoco.MjData(model)
        for j in asset.joints:
            far = (
                j.range[1]
                if abs(j.range[1] - j.closed_value) >= abs(j.range[0] - j.closed_value)
                else j.range[0]
            )
            adr = model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "a_" + j.name)]
            data.qpos[adr] = j.closed_value + open_fraction * (far - j.closed_value)
        mujoco.mj_forward(model, data)
    lo, hi = asset.aabb
    cam = mujoco.MjvCamera()
    cam.type = mujoco.mjtCamera.mjCAMERA_FREE
    cam.lookat[:] = (lo + hi) / 2
    ext = hi - lo
    cam.distance = float(np.linalg.norm(ext)) * 1.25 / math.tan(math.radians(45 / 2)) / 2 + 1e-3
    cam.azimuth, cam.elevation = azimuth, elevation
    model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
    model.vis.global_.offheight = max(model.vis.global_.offheight, height)
    model.vis.map.znear = 0.001 if asset.size < 0.2 else 0.01
    with mujoco.Renderer(model, height=height, width=width) as renderer:
        renderer.update_scene(data, camera=cam)
        return renderer.render().copy()


def save_png(rgb: np.ndarray, path: str | Path) -> Path:
    import io

    from PIL import Image

    from anomalygen.runfolder import atomic_write_bytes

    buf = io.BytesIO()
    Image.fromarray(rgb).save(buf, format="PNG")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(path, buf.getvalue())
    return path


GALLERY_POSE = {"Eyeglasses": 1.0, "Chair": 0.0, "USB": 0.0}


def gallery(names: list[str], seed: int = 0, *, cell: int = 200, cols: int = 8, real: bool = False) -> np.ndarray:
    """A labelled contact sheet: one thumbnail per name (e.g. the 44 target categories); ``real``
    shows the real model a scene draws where a name has one."""
    from PIL import Image, ImageDraw

    from anomalygen.assets.core import draw as draw_asset

    rows = math.ceil(len(names) / cols)
    label_h = 18
    sheet = Image.new("RGB", (cols * cell, rows * (cell + label_h)), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    for i, name in enumerate(names):
        asset = draw_asset(name, seed, real=real)
        # part-open pose shows what moves; glasses read best with the temples fully unfolded
        rgb = render_asset(asset, width=cell, height=cell, open_fraction=GALLERY_POSE.get(name, 0.35))
        x, y = (i % cols) * cell, (i // cols) * (cell + label_h)
        sheet.paste(Image.fromarray(rgb), (x, y))
        draw.text((x + 4, y + cell + 2), name, fill=(0, 0, 0))
    return np.asarray(sheet)
