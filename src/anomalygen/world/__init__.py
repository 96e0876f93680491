"""The world a built scene is, as the robot and any outside agent perceive it.

Below both the builder (``anomalygen.scene``, which makes a scene) and the robot's side (detect,
plan, learn, skills, which act on one), so that neither reaches the other: the scene graph
(``graph``: objects, states, relations read off the simulator), the simulator state (``state``),
cavities and tops, the state rules of parts (``states``), renders, observation sensors, the furnished
floor (``room``), the perceived scene with the answer key removed (``perception``) and the public
Gymnasium env (``env``). Nothing here reads the answer key (``anomalygen.truth``) or the referee.
"""

import os

# Headless by default: MuJoCo picks its GL backend when it is first imported.
if not os.environ.get("DISPLAY"):
    os.environ.setdefault("MUJOCO_GL", "egl")
    os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
