"""Scene stage: from a TaskProposal to a validated MuJoCo scene with robot, renders, scene graph and env.

Modules: casting (which objects, which roles), asset_choice (one asset), layout (placement solver),
furniture (support surfaces), compose (the MjSpec: room, cameras, the robot from ``anomalygen.robot``),
build (one scene), validate, graph (SceneGraph), render, sensors, env (Gymnasium), stage
(``anomalygen build``). The robot itself (Franka Panda + suction on a mobile base) lives in
``anomalygen.robot``.
"""

import os

# Headless by default: MuJoCo picks its GL backend when it is first imported.
if not os.environ.get("DISPLAY"):
    os.environ.setdefault("MUJOCO_GL", "egl")
    os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
