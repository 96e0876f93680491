"""The learn test scene: the cabinet-door scene (``support/door_scene.py``) furnished
with a table, a bin and two loose objects, optionally with a box obstacle for the motion tests."""

from __future__ import annotations

from support import door_scene
from support.door_scene import add_box


def furnish(wb) -> list[str]:
    """A table with a box on it, a bin, and a toy on the floor; returns the loose objects."""
    free = []
    table = wb.add_body(name="table_0", pos=[0.62, 0.25, 0.0])
    add_box(table, "table_0_top", [0.4, 0.5, 0.04], [0, 0, 0.38], [0.55, 0.4, 0.25, 1])
    for i, (dx, dy) in enumerate([(-0.17, -0.22), (0.17, -0.22), (-0.17, 0.22), (0.17, 0.22)]):
        add_box(table, f"table_0_leg{i}", [0.03, 0.03, 0.36], [dx, dy, 0.18], [0.45, 0.3, 0.2, 1])
    binb = wb.add_body(name="bin_0", pos=[0.45, -0.45, 0.0])
    add_box(binb, "bin_0_bottom", [0.24, 0.24, 0.01], [0, 0, 0.005], [0.2, 0.4, 0.7, 1])
    for i, (p, s) in enumerate([([0.115, 0, 0.07], [0.01, 0.24, 0.14]), ([-0.115, 0, 0.07], [0.01, 0.24, 0.14]),
                                ([0, 0.115, 0.07], [0.24, 0.01, 0.14]), ([0, -0.115, 0.07], [0.24, 0.01, 0.14])]):
        add_box(binb, f"bin_0_wall{i}", s, p, [0.2, 0.4, 0.7, 1])
    for name, pos, size, rgba in (("box_0", [0.55, 0.2, 0.43], [0.05, 0.05, 0.06], [0.9, 0.2, 0.2, 1]),
                                  ("toy_0", [0.5, -0.1, 0.02], [0.04, 0.04, 0.04], [0.9, 0.8, 0.1, 1])):
        b = wb.add_body(name=name, pos=pos)
        b.add_freejoint(name=f"{name}_free")
        add_box(b, f"{name}_geom", size, [0, 0, 0], rgba, mass=0.1, friction=[1.0, 0.01, 0.001])
        free.append(name)
    return free


def build(*, with_cabinet=True, with_objects=True, door_open=1.2) -> door_scene.DoorScene:
    """The compiled test scene at the home pose with the door ``door_open`` rad open."""
    return door_scene.build(with_cabinet=with_cabinet, door_open=door_open, furnish=furnish if with_objects else None)


def scene_with_obstacle(obstacle_at=None, half=0.03):
    """(model, data) of the test scene at the home pose, cabinet door 1.2 rad open, plus an optional
    ``half``-sized box obstacle centred at ``obstacle_at``."""
    import mujoco

    from anomalygen.robot.agent import Agent

    spec, _ = door_scene.build_spec(furnish=furnish)
    if obstacle_at is not None:
        spec.worldbody.add_geom(name="obstacle", type=mujoco.mjtGeom.mjGEOM_BOX, size=[half] * 3,
                                pos=list(obstacle_at), rgba=[1, 0, 0, 1])
    m = spec.compile()
    d = mujoco.MjData(m)
    Agent(m).set_home(d, (0.0, 0.0, 0.0))
    d.joint("cabinet_0:door_hinge").qpos[0] = 1.2
    mujoco.mj_forward(m, d)
    return m, d
