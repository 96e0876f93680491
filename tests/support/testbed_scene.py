"""The learn test scene (``anomalygen.rl.testbed``), optionally with a box obstacle, for motion tests."""

from __future__ import annotations


def scene_with_obstacle(obstacle_at=None, half=0.03):
    """(model, data) of the test scene at the home pose, cabinet door 1.2 rad open, plus an optional
    ``half``-sized box obstacle centred at ``obstacle_at``."""
    import mujoco

    from anomalygen.rl.testbed import build_spec
    from anomalygen.scene.robot import set_home

    spec, _ = build_spec()
    if obstacle_at is not None:
        spec.worldbody.add_geom(name="obstacle", type=mujoco.mjtGeom.mjGEOM_BOX, size=[half] * 3,
                                pos=list(obstacle_at), rgba=[1, 0, 0, 1])
    m = spec.compile()
    d = mujoco.MjData(m)
    set_home(m, d, (0.0, 0.0, 0.0))
    d.joint("cabinet_0:door_hinge").qpos[0] = 1.2
    mujoco.mj_forward(m, d)
    return m, d
