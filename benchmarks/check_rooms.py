"""Do a run's scenes read as rooms? Issue 26's acceptance checks, on every built scene of a run folder.

For each valid scene: every window and door is mounted in a wall (its box against the back or side
wall, a window's bottom at the sill height, a door's on the floor); the front render's background is
wall or floor everywhere (no empty pixels), its top edge shows no floor (walls, or things standing before
them), at least 5 % of it is wall; and the object at fault (the
builder's ``$hazard``, else ``$target``) is not covered by the robot in the front and top renders,
measured again from scene.xml (its bounding box projected into each camera, the robot's share of
its visible pixels). Prints the failures and one JSON line.

    .venv/bin/python benchmarks/check_rooms.py --run RUN_FOLDER
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

TOP_ROWS = 2  # rows at the top of the front render that must show no floor (walls, or things before them)
WALL_MIN = 0.05  # share of the front render that must be wall
HEIGHT_TOL = 0.03  # m


def check_scene(folder: Path, width: int, height: int) -> list[str]:
    from anomalygen.mjgeom import FLOOR_GEOM
    from anomalygen.scene import viewpoint, walls
    from anomalygen.scene.build import at_fault
    from anomalygen.world.graph import load_scene
    from anomalygen.world.render import SceneRenderer

    model, data, spec = load_scene(folder)
    problems = []
    for o in spec.objects:
        bottom = walls.mount_height(o.asset.category)
        if bottom is None:
            continue
        lo, hi = viewpoint.object_aabb(model, data, o.name)
        if walls.wall_of(lo, hi) is None or abs(lo[2] - bottom) > HEIGHT_TOL:
            problems.append(f"{o.name} not mounted in a wall (box {np.round(lo, 2)}..{np.round(hi, 2)})")
    wall = walls.wall_geoms(model, spec)
    with SceneRenderer(model, width, height) as r:
        seg = r.segment(data, "front")
        if np.any(seg < 0):
            problems.append(f"front render: {int((seg < 0).sum())} px of empty background")
        top = seg[:TOP_ROWS]
        floor = model.geom(FLOOR_GEOM).id
        if np.any(top == floor):
            problems.append(f"front render: the top edge shows {int((top == floor).sum())} px of floor behind the objects")
        if np.isin(seg, wall).mean() < WALL_MIN:
            problems.append(f"front render: only {np.isin(seg, wall).mean():.0%} of it is wall")
        fault = at_fault(spec.bindings)
        if fault is not None:
            for check in viewpoint.fault_coverage(r, model, data, fault):
                if not check.passed:
                    problems.append(check.detail)
    return problems


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--run", required=True)
    a = ap.parse_args()
    from anomalygen.config import Settings
    from anomalygen.scene.stage import scene_ok

    b = Settings().build
    scenes = sorted(p for p in (Path(a.run) / "scenes").iterdir() if p.is_dir() and scene_ok(p))
    failed = {}
    for folder in scenes:
        problems = check_scene(folder, b.render_width, b.render_height)
        if problems:
            failed[folder.name] = problems
            print(folder.name, "; ".join(problems))
    print(json.dumps({"name": "rooms", "scenes": len(scenes), "ok": len(scenes) - len(failed), "failed": sorted(failed)}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
