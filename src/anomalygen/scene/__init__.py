"""The builder: from a TaskProposal to a validated MuJoCo scene folder with its hidden answer key.

Modules: casting (which objects, which roles), asset_choice (one asset), layout (placement solver),
furniture (support surfaces), walls, viewpoint (the room cameras), compose (the MjSpec: room, cameras,
the robot from ``anomalygen.robot``), placement, instances, judgement and mix (near-misses, a second
hazard, hazard-free scenes), set_states, build (one scene), validate, verify, llm_engine, stage
(``anomalygen build``). What a built scene is once made (scene graph, state, renders, sensors, the
env) lives in ``anomalygen.world``; the answer key the builder writes lives in ``anomalygen.truth``.
"""

import anomalygen.world  # noqa: F401  (headless GL before MuJoCo is first imported)
