"""Declared cavities of placed objects as boxes on the bodies they move with (``PlacedCavity``).

Why: "inside" must mean inside a container's declared interior. Assets declare their cavities in the
frame of their root at the closed state (``assets.model.Cavity``); a drawer's bin moves with the
drawer, a cupboard's space stays with the cupboard. The builder records each cavity on the body it
moves with, in that body's frame, so the scene graph can place it from live body poses with no asset
at hand. Scenes built before the record existed get the same records rebuilt from their asset refs.
"""

from __future__ import annotations

import numpy as np

from anomalygen.schema import DOOR, PlacedCavity, PlacedObject, part_labels

SUPPORT_PREFIX = "support-"  # asset ids of the builder's plain support furniture (tables, counters): no cavity


def placed_cavities(model, name: str, asset) -> list[PlacedCavity]:
    """The cavities of ``asset`` placed as object ``name`` in the compiled ``model``.

    A cavity closed by a slide moves with the slide's body (a drawer bin), unless the slide is a
    door (a sliding cabinet door moves across the space it closes); any other stays with the object's body. Poses come from the model at its reference configuration (every joint closed at 0).
    """
    import mujoco

    if not asset.cavities:
        return []
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    root = model.body(name).id
    root_pos, root_mat = data.xpos[root].copy(), data.xmat[root].reshape(3, 3).copy()
    joints = {j.name: j for j in asset.joints}
    out = []
    for cav in asset.cavities:
        joint = joints.get(cav.joint) if cav.joint else None
        moves_with = joint is not None and joint.type == "slide" and joint.body and part_labels.canonical(joint.label) != DOOR
        body_name = f"{name}/{joint.body}" if moves_with else name
        body = model.body(body_name).id
        world = root_pos + root_mat @ np.asarray(cav.center, float)
        pos, mat = data.xpos[body], data.xmat[body].reshape(3, 3)
        local = mat.T @ (world - pos)
        out.append(PlacedCavity(
            name=cav.name,
            body=body_name,
            center=[float(v) for v in local],
            half_extents=[float(v) for v in cav.half_extents],
            opening=cav.opening,
            joint=f"{name}/{cav.joint}" if cav.joint else None,
        ))
    return out


def cavities_of(model, obj: PlacedObject) -> list[PlacedCavity]:
    """The object's recorded cavities; for a scene built before they were recorded (``None``), the
    records rebuilt from its asset reference (plain support furniture has none)."""
    if obj.cavities is not None:
        return list(obj.cavities)
    if obj.asset.asset_id.startswith(SUPPORT_PREFIX):
        return []
    from anomalygen.assets.core import from_ref

    try:
        asset = from_ref(obj.asset)
    except (KeyError, ValueError, OSError):
        return []
    return placed_cavities(model, obj.name, asset)
