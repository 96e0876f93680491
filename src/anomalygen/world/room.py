"""The furnished floor every built room shares: a fact of the world, read by the builder's layout
and by the robot's skills (a spot on the floor stays inside it)."""

from __future__ import annotations

import numpy as np

ROOM_HALF = np.array([1.9, 2.0])  # m: half the floor area used, around ROOM_CENTER
ROOM_CENTER = np.array([1.0, 0.0])  # m: world (x, y) of the middle of that floor area
