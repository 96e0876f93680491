"""Judge a simulator state: let go of what the robot holds, take the robot away, let the scene settle.

Why: the robot is judged on the scene it leaves behind. An object still on the suction cup is put
away nowhere and supported by nothing; a door the cup still pushes shut may swing open once it lets
go. So the referee works on a copy of the model and state (a live episode is left untouched),
switches off every weld by which the robot holds an object or a part, makes the robot's geoms pass
through everything (it walks away: what rested on its cup falls), and steps the physics until the
loose objects rest. What falls, falls. The scene graph of that state is what the verdict reads.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np

from anomalygen.scene_files import SCENE_SPEC
from anomalygen.schema import SceneGraph, SceneSpec, Verdict

SETTLE_S = 1.0  # s of simulated time after the release (a knife dropped from 1 m lands in 0.45 s)
EXTRA_SETTLE_S = 1.0  # s more when something still moves (a bottle rolling off a table)
REST_SPEED = 0.05  # m/s: loose objects slower than this have come to rest


def copy_state(model, data):
    """A copy of ``model`` and a fresh data for it holding ``data``'s full integration state."""
    import mujoco

    from anomalygen.world.state import get_state, set_state

    m = copy.deepcopy(model)
    d = mujoco.MjData(m)
    set_state(m, d, get_state(model, data))
    return m, d


def released_and_settled(model, data, spec: SceneSpec) -> tuple[object, object, list[str], float]:
    """(model copy, settled data copy, objects that were held, simulated seconds) for ``data``."""
    import mujoco

    from anomalygen.world.graph import geom_owners, held_objects, robot_constraints

    m, d = copy_state(model, data)
    released = held_objects(m, d, spec)
    for eq in robot_constraints(m, d, spec):
        d.eq_active[eq] = 0
    robot = (geom_owners(m, spec) < 0) & (m.geom_bodyid != 0)  # owned by no object and not the room
    m.geom_contype[robot] = 0
    m.geom_conaffinity[robot] = 0
    steps = max(1, int(round(SETTLE_S / m.opt.timestep)))
    mujoco.mj_step(m, d, nstep=steps)
    settled = SETTLE_S
    if _fastest(m, d, spec) > REST_SPEED:
        mujoco.mj_step(m, d, nstep=max(1, int(round(EXTRA_SETTLE_S / m.opt.timestep))))
        settled += EXTRA_SETTLE_S
    mujoco.mj_forward(m, d)
    return m, d, released, settled


def _fastest(model, data, spec: SceneSpec) -> float:
    speeds = [float(np.linalg.norm(data.joint(f"{o.name}/free").qvel[:3])) for o in spec.objects if not o.fixed]
    return max(speeds, default=0.0)


def settled_graph(model, data, spec: SceneSpec) -> tuple[SceneGraph, list[str], float]:
    """The scene graph the referee judges: (graph of the released, settled copy, released objects, seconds)."""
    from anomalygen.world.graph import scene_graph

    m, d, released, settled = released_and_settled(model, data, spec)
    return scene_graph(m, d, spec), released, settled


def initial_graph(model, spec: SceneSpec) -> SceneGraph:
    """The scene graph of the settled scene as built (the model's ``init`` keyframe), by today's rules."""
    import mujoco

    from anomalygen.world.graph import reset_to_initial, scene_graph

    d = mujoco.MjData(model)
    reset_to_initial(model, d)
    return scene_graph(model, d, spec)


def judge(scene_dir: str | Path, model, data, *, task_id: str | None = None, seed: int | None = None) -> Verdict:
    """The referee's verdict on a simulator state of the built scene in ``scene_dir``.

    ``model`` and ``data`` may be a live episode's (an outside policy's, through ``make_env``): they are
    copied, never changed. Every hazard of the scene's truth.json comes back judged (``Verdict.hazards``),
    with the new hazards, the near-misses acted on and the objects that were still held.
    """
    from anomalygen.knowledge import load_kb
    from anomalygen.referee.verdict import verdict_on
    from anomalygen.runfolder import read_model
    from anomalygen.truth.manifest import load_manifest

    scene_dir = Path(scene_dir)
    manifest = load_manifest(scene_dir)
    if manifest is None:
        raise FileNotFoundError(f"no truth.json in {scene_dir}: a scene built before the truth existed cannot be judged")
    spec = read_model(scene_dir / SCENE_SPEC, SceneSpec)
    final, released, settled = settled_graph(model, data, spec)
    return verdict_on(manifest, initial_graph(model, spec), final, load_kb(),
                      task_id=task_id if task_id is not None else manifest.task_id, seed=seed,
                      released=released, settle_s=settled)
