"""The top an object rests on, as one surface: the edge a thing stands near is the edge of the whole
top, not of one board of it (``world/graph.py`` measures ``distance_to_edge`` against it)."""

from __future__ import annotations

import numpy as np

TOP_TOL = 0.01  # m: boards of one top are level and touch within this


def on_fixed_frame(model, body: int, root: int) -> bool:
    """``body`` is ``root`` or welded to it: no joint between them but the root's own free joint (a
    door on its hinge is not part of a cabinet's top)."""
    while body != root:
        adr, n = int(model.body_jntadr[body]), int(model.body_jntnum[body])
        if body == 0 or any(model.jnt_type[j] != 0 for j in range(adr, adr + n)):  # 0: mjJNT_FREE
            return False
        body = int(model.body_parentid[body])
    return True


def top_surface(model, owner: np.ndarray, boxes, geom: int, root: int) -> tuple[np.ndarray, np.ndarray]:
    """World box of the whole top that ``geom`` belongs to: the support's solid geoms of its fixed
    frame that are level with it and touch it, or each other, within ``TOP_TOL``. A cabinet's top
    may be several boards; measured against the one board a pan touches first, a pan in the middle
    of the top read as 15 cm over its edge. Parts on a joint (a door swung open to the same height)
    are not the top."""
    glo, ghi = boxes

    level = [g for g in np.flatnonzero(owner == owner[geom])
             if abs(ghi[g][2] - ghi[geom][2]) <= TOP_TOL and (model.geom_contype[g] or model.geom_conaffinity[g])
             and on_fixed_frame(model, int(model.geom_bodyid[g]), root)]
    lo, hi = glo[geom].copy(), ghi[geom].copy()
    grown = True
    while grown:
        grown = False
        for g in level:
            if np.all(glo[g][:2] <= hi[:2] + TOP_TOL) and np.all(ghi[g][:2] >= lo[:2] - TOP_TOL) \
                    and (np.any(glo[g][:2] < lo[:2]) or np.any(ghi[g][:2] > hi[:2])):
                lo[:2], hi[:2] = np.minimum(lo[:2], glo[g][:2]), np.maximum(hi[:2], ghi[g][:2])
                grown = True
    return lo, hi
