"""Frame and body-tree helpers on a compiled MuJoCo model: the pose of one frame in another, and the
geoms of a body's subtree. Plain MuJoCo arithmetic that the agent, the motion planner and the skills
all need; it names no robot element."""

from __future__ import annotations

import numpy as np


def relative_pose(pos1, quat1, pos2, quat2) -> tuple[np.ndarray, np.ndarray]:
    """Pose of frame 2 expressed in frame 1."""
    import mujoco

    neg = np.zeros(4)
    mujoco.mju_negQuat(neg, quat1)
    relpos = np.zeros(3)
    mujoco.mju_rotVecQuat(relpos, np.asarray(pos2) - np.asarray(pos1), neg)
    relquat = np.zeros(4)
    mujoco.mju_mulQuat(relquat, neg, np.asarray(quat2, dtype=float))
    return relpos, relquat


def subtree_geoms(model, body: int) -> np.ndarray:
    """Boolean mask of geoms attached to ``body`` or its descendants."""
    mask = np.zeros(model.ngeom, dtype=bool)
    bodies = {body}
    for b in range(body + 1, model.nbody):
        if model.body_parentid[b] in bodies:
            bodies.add(b)
    for g in range(model.ngeom):
        if model.geom_bodyid[g] in bodies:
            mask[g] = True
    return mask
