"""A small self-contained test scene: the project's robot, a table, free objects, a bin, a cabinet door.

Skills are developed and tested here independently of the scene builder (a built scene has the same
robot, names and suction welds, so the same code runs on both). It is also the environment of the SAC
benchmark (close a cabinet door from a random start), which must not change when the scene
builder's layouts do.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

TIMESTEP = 0.005


@dataclass
class Testbed:
    model: object
    data: object
    free_objects: list[str] = field(default_factory=list)
    door_joint: str = "cabinet_0:door_hinge"
    door_range: tuple[float, float] = (0.0, 1.6)


def look_at(eye, target) -> list[float]:
    """Camera ``xyaxes`` so a camera at ``eye`` looks at ``target`` with the world z up."""
    fwd = np.asarray(target, dtype=float) - np.asarray(eye, dtype=float)
    fwd /= np.linalg.norm(fwd)
    x = np.cross(fwd, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    y = np.cross(x, fwd)
    return [*x.tolist(), *y.tolist()]


def _box(body, name, size, pos, rgba, **kw):
    import mujoco

    return body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_BOX, size=[s / 2 for s in size], pos=pos, rgba=rgba, **kw)


def build_spec(*, with_cabinet=True, with_objects=True, door_open=1.2):
    """MjSpec of the test scene (robot at the origin facing +x)."""
    import mujoco

    from anomalygen.scene.robot_model import add_suction_welds, build_robot_spec

    spec = build_robot_spec((0.0, 0.0, 0.0))
    spec.option.timestep = TIMESTEP
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    wb = spec.worldbody
    wb.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[5, 5, 0.1], rgba=[0.8, 0.78, 0.72, 1])
    wb.add_light(pos=[0, 0, 3], dir=[0, 0, -1], diffuse=[0.8, 0.8, 0.8])
    wb.add_camera(name="front", pos=[0.9, 1.5, 1.3], xyaxes=look_at([0.9, 1.5, 1.3], [0.5, -0.1, 0.35]))
    free = []
    if with_objects:
        table = wb.add_body(name="table_0", pos=[0.62, 0.25, 0.0])
        _box(table, "table_0_top", [0.4, 0.5, 0.04], [0, 0, 0.38], [0.55, 0.4, 0.25, 1])
        for i, (dx, dy) in enumerate([(-0.17, -0.22), (0.17, -0.22), (-0.17, 0.22), (0.17, 0.22)]):
            _box(table, f"table_0_leg{i}", [0.03, 0.03, 0.36], [dx, dy, 0.18], [0.45, 0.3, 0.2, 1])
        binb = wb.add_body(name="bin_0", pos=[0.45, -0.45, 0.0])
        _box(binb, "bin_0_bottom", [0.24, 0.24, 0.01], [0, 0, 0.005], [0.2, 0.4, 0.7, 1])
        for i, (p, s) in enumerate([([0.115, 0, 0.07], [0.01, 0.24, 0.14]), ([-0.115, 0, 0.07], [0.01, 0.24, 0.14]),
                                    ([0, 0.115, 0.07], [0.24, 0.01, 0.14]), ([0, -0.115, 0.07], [0.24, 0.01, 0.14])]):
            _box(binb, f"bin_0_wall{i}", s, p, [0.2, 0.4, 0.7, 1])
        for name, pos, size, rgba in (("box_0", [0.55, 0.2, 0.43], [0.05, 0.05, 0.06], [0.9, 0.2, 0.2, 1]),
                                      ("toy_0", [0.5, -0.1, 0.02], [0.04, 0.04, 0.04], [0.9, 0.8, 0.1, 1])):
            b = wb.add_body(name=name, pos=pos)
            b.add_freejoint(name=f"{name}_free")
            _box(b, f"{name}_geom", size, [0, 0, 0], rgba, mass=0.1, friction=[1.0, 0.01, 0.001])
            free.append(name)
    if with_cabinet:
        # Cabinet against +y side; its open front faces -y... keep it simple: front faces the robot (-x).
        cab = wb.add_body(name="cabinet_0", pos=[0.85, -0.05, 0.0])
        d, w, h, z0 = 0.3, 0.36, 0.36, 0.3
        _box(cab, "cabinet_0_back", [0.02, w, h], [d / 2, 0, z0 + h / 2], [0.7, 0.7, 0.75, 1])
        _box(cab, "cabinet_0_bottom", [d, w, 0.02], [0, 0, z0], [0.7, 0.7, 0.75, 1])
        _box(cab, "cabinet_0_top", [d, w, 0.02], [0, 0, z0 + h], [0.7, 0.7, 0.75, 1])
        _box(cab, "cabinet_0_left", [d, 0.02, h], [0, w / 2, z0 + h / 2], [0.7, 0.7, 0.75, 1])
        _box(cab, "cabinet_0_right", [d, 0.02, h], [0, -w / 2, z0 + h / 2], [0.7, 0.7, 0.75, 1])
        _box(cab, "cabinet_0_leg", [d, w, z0], [0, 0, z0 / 2], [0.6, 0.6, 0.65, 1])
        # Door hinged at the front-right edge (y = -w/2), swinging towards the robot.
        door = cab.add_body(name="cabinet_0:door", pos=[-d / 2 - 0.012, -w / 2, z0 + h / 2])
        door.add_joint(name="cabinet_0:door_hinge", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1],
                       range=[0.0, 1.6], damping=0.5, armature=0.01, frictionloss=0.05)
        _box(door, "cabinet_0_door_panel", [0.02, w, h], [0, w / 2, 0], [0.5, 0.55, 0.7, 1], mass=0.8)
        _box(door, "cabinet_0_door_handle", [0.03, 0.02, 0.1], [-0.025, w - 0.05, 0], [0.2, 0.2, 0.2, 1], mass=0.05)
        door.add_site(name="cabinet_0:door_handle", pos=[-0.04, w - 0.05, 0], size=[0.01, 0, 0])
    add_suction_welds(spec, free)
    return spec, free


def build(*, with_cabinet=True, with_objects=True, door_open=1.2) -> Testbed:
    """Compile the test scene and put the robot at home with the door ``door_open`` rad open."""
    import mujoco

    from anomalygen.scene.robot import set_home

    spec, free = build_spec(with_cabinet=with_cabinet, with_objects=with_objects, door_open=door_open)
    model = spec.compile()
    data = mujoco.MjData(model)
    set_home(model, data, (0.0, 0.0, 0.0))
    if with_cabinet:
        data.joint("cabinet_0:door_hinge").qpos[0] = door_open
    mujoco.mj_forward(model, data)
    return Testbed(model, data, free)
