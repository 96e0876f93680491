"""Geometry read off any MuJoCo model and state: the world boxes of its geoms and the floor's name.

Why here, at the bottom: the robot's motion driver, the skills, the scene graph and the builder all
measure geoms the same way, and the robot sits below the world package that reads a built scene.
"""

from __future__ import annotations

import numpy as np

FLOOR_GEOM = "floor"  # the name the room composer gives the floor plane


def geom_world_aabbs(model, data) -> tuple[np.ndarray, np.ndarray]:
    """World-frame (min, max) corners of every geom's bounding box, shape (ngeom, 3) each."""
    import mujoco

    center_local = model.geom_aabb[:, :3]
    half_local = model.geom_aabb[:, 3:]
    mats = data.geom_xmat.reshape(-1, 3, 3)
    center = data.geom_xpos + np.einsum("gij,gj->gi", mats, center_local)
    half = np.einsum("gij,gj->gi", np.abs(mats), half_local)
    # Balls and ellipsoids get their exact box: the turned local box of a ball rolling in a basket
    # grew by up to 40 % (its bottom 3 cm under the floor) and the ball was no longer 'inside'.
    # (Capsules and cylinders keep the turned box: cable links and knobs are measured as before.)
    size, kind = model.geom_size, model.geom_type
    sph = kind == mujoco.mjtGeom.mjGEOM_SPHERE
    half[sph] = size[sph, :1]
    ell = kind == mujoco.mjtGeom.mjGEOM_ELLIPSOID
    half[ell] = np.sqrt(np.einsum("gij,gj->gi", mats[ell] ** 2, size[ell] ** 2))
    return center - half, center + half
