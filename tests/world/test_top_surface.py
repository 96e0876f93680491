"""The edge a thing rests near is the edge of the whole top it stands on, not of one board of it."""

from __future__ import annotations

import mujoco
import numpy as np

from anomalygen.mjgeom import geom_world_aabbs
from anomalygen.world.tops import top_surface

# A cabinet whose top is two level boards side by side, a door on a hinge whose top edge is level
# with them, and a separate board 30 cm away at the same height (another piece of furniture would be
# another object; this one is part of the cabinet but does not touch the top).
XML = """
<mujoco><worldbody>
  <body name="cab" pos="0 0 0">
    <geom name="left" type="box" size="0.2 0.3 0.01" pos="-0.2 0 0.5"/>
    <geom name="right" type="box" size="0.2 0.3 0.01" pos="0.2 0 0.5"/>
    <geom name="apart" type="box" size="0.05 0.05 0.01" pos="0.8 0 0.5"/>
    <body name="cab/door" pos="0 -0.31 0.25">
      <joint name="hinge" type="hinge" axis="0 0 1"/>
      <geom name="door" type="box" size="0.4 0.01 0.26" pos="0 0 0"/>
    </body>
  </body>
</worldbody></mujoco>
"""


def test_the_top_is_every_level_board_that_touches_not_a_door_or_a_board_apart():
    model = mujoco.MjModel.from_xml_string(XML)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    owner = np.zeros(model.ngeom, dtype=int)  # every geom belongs to the one object, the cabinet
    boxes = geom_world_aabbs(model, data)
    right = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, "right")
    lo, hi = top_surface(model, owner, boxes, right, model.body("cab").id)
    assert np.allclose(lo[:2], [-0.4, -0.3]) and np.allclose(hi[:2], [0.4, 0.3])  # both boards, no door, no apart
