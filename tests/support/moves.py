"""Test doubles for a robot's end state: put objects somewhere by hand, or hold one on the suction cup.

Only for tests of the graph and the referee: a real robot would have carried them there. Each helper
edits ``data`` (and the weld's pose in ``model``) through MuJoCo alone, finding bodies and welds from
the model's structure (the scene graph's index), so it needs no robot module.
"""

from __future__ import annotations

import math

import numpy as np


def put(model, data, name: str, center, *, yaw: float = 0.0, size_z: float | None = None) -> None:
    """Teleport loose object ``name`` so its bounding box's centre is at ``center`` (at rest, turned by
    ``yaw`` about z). ``size_z``: its height (the box's centre sits that half above its bottom)."""
    import mujoco

    joint = model.joint(f"{name}/free")
    adr, dof = int(joint.qposadr[0]), int(joint.dofadr[0])
    half = 0.5 * (size_z or 0.0)
    data.qpos[adr:adr + 3] = [center[0], center[1], center[2] - half]
    data.qpos[adr + 3:adr + 7] = [math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2)]
    data.qvel[dof:dof + 6] = 0.0
    mujoco.mj_forward(model, data)


def hold(model, data, spec, name: str, below_cup: float = 0.08) -> int:
    """Weld loose object ``name`` to the robot's cup where the cup is now, ``below_cup`` metres under it.

    The weld is the scene's own (one per loose object); returns its id."""
    import mujoco

    from anomalygen.world.graph import _index, _subtree_bodies

    idx = _index(model, spec)
    eq = int(idx.hold_eqs[list(idx.hold_owner).index(idx.names.index(name))])
    cup, obj = int(model.eq_obj1id[eq]), int(model.eq_obj2id[eq])  # body1 holds body2 (the weld's pose is body2 in body1)
    assert obj in _subtree_bodies(model, model.body(name).id), "the scene's suction weld holds the object as body2"
    joint = model.joint(f"{name}/free")
    adr = int(joint.qposadr[0])
    mujoco.mj_forward(model, data)
    data.qpos[adr:adr + 3] = data.xpos[cup] - np.array([0.0, 0.0, below_cup])
    data.qpos[adr + 3:adr + 7] = [1.0, 0.0, 0.0, 0.0]
    mujoco.mj_forward(model, data)
    neg, relpos, relquat = np.zeros(4), np.zeros(3), np.zeros(4)
    mujoco.mju_negQuat(neg, data.xquat[cup])
    mujoco.mju_rotVecQuat(relpos, data.xpos[obj] - data.xpos[cup], neg)
    mujoco.mju_mulQuat(relquat, neg, data.xquat[obj])
    model.eq_data[eq, 0:3] = 0.0
    model.eq_data[eq, 3:6] = relpos
    model.eq_data[eq, 6:10] = relquat
    model.eq_data[eq, 10] = 1.0
    data.eq_active[eq] = 1
    mujoco.mj_forward(model, data)
    return eq


def cavity_center(model, data, spec, owner: str, cavity: str) -> np.ndarray:
    """World centre of ``owner``'s declared cavity ``cavity`` in the current state."""
    obj = next(o for o in spec.objects if o.name == owner)
    cav = next(c for c in obj.cavities if c.name == cavity)
    body = model.body(cav.body).id
    return data.xpos[body] + data.xmat[body].reshape(3, 3) @ np.asarray(cav.center)
