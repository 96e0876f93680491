"""The cabinet-door scene of ``DoorCloseEnv`` and the SAC benchmark: the project's robot, a floor and a
cabinet whose door swings toward it.

Test and benchmark support, not part of the package. Self-contained on purpose: the benchmark must
not change when the scene builder's layouts do, and a built scene has the same robot, names and
suction welds, so the same skills run on both. Callers may ``furnish`` the room before the cabinet
goes in (the tests add a table, a bin and loose objects).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from anomalygen.scene.viewpoint import look_at_xyaxes

TIMESTEP = 0.005


@dataclass
class DoorScene:
    model: object
    data: object
    free_objects: list[str] = field(default_factory=list)
    door_joint: str = "cabinet_0:door_hinge"
    door_range: tuple[float, float] = (0.0, 1.6)


def add_box(body, name, size, pos, rgba, **kw):
    """A box geom of full ``size`` (MuJoCo takes half sizes)."""
    import mujoco

    return body.add_geom(name=name, type=mujoco.mjtGeom.mjGEOM_BOX, size=[s / 2 for s in size], pos=pos, rgba=rgba, **kw)


def build_spec(*, with_cabinet=True, furnish: Callable[[object], list[str]] | None = None):
    """MjSpec of the scene (robot at the origin facing +x) and its loose objects' names.

    ``furnish(worldbody)`` adds more things and returns the loose objects among them (they get
    suction welds like the scene builder's)."""
    import mujoco

    from anomalygen.robot.agent import Agent

    spec = Agent.build_spec((0.0, 0.0, 0.0))
    spec.option.timestep = TIMESTEP
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    wb = spec.worldbody
    wb.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, size=[5, 5, 0.1], rgba=[0.8, 0.78, 0.72, 1])
    wb.add_light(pos=[0, 0, 3], dir=[0, 0, -1], diffuse=[0.8, 0.8, 0.8])
    wb.add_camera(name="front", pos=[0.9, 1.5, 1.3], xyaxes=look_at_xyaxes([0.9, 1.5, 1.3], [0.5, -0.1, 0.35]))
    free = furnish(wb) if furnish is not None else []
    if with_cabinet:
        # Cabinet against +y side; its open front faces -y... keep it simple: front faces the robot (-x).
        cab = wb.add_body(name="cabinet_0", pos=[0.85, -0.05, 0.0])
        d, w, h, z0 = 0.3, 0.36, 0.36, 0.3
        add_box(cab, "cabinet_0_back", [0.02, w, h], [d / 2, 0, z0 + h / 2], [0.7, 0.7, 0.75, 1])
        add_box(cab, "cabinet_0_bottom", [d, w, 0.02], [0, 0, z0], [0.7, 0.7, 0.75, 1])
        add_box(cab, "cabinet_0_top", [d, w, 0.02], [0, 0, z0 + h], [0.7, 0.7, 0.75, 1])
        add_box(cab, "cabinet_0_left", [d, 0.02, h], [0, w / 2, z0 + h / 2], [0.7, 0.7, 0.75, 1])
        add_box(cab, "cabinet_0_right", [d, 0.02, h], [0, -w / 2, z0 + h / 2], [0.7, 0.7, 0.75, 1])
        add_box(cab, "cabinet_0_leg", [d, w, z0], [0, 0, z0 / 2], [0.6, 0.6, 0.65, 1])
        # Door hinged at the front-right edge (y = -w/2), swinging towards the robot.
        door = cab.add_body(name="cabinet_0:door", pos=[-d / 2 - 0.012, -w / 2, z0 + h / 2])
        door.add_joint(name="cabinet_0:door_hinge", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1],
                       range=[0.0, 1.6], damping=0.5, armature=0.01, frictionloss=0.05)
        add_box(door, "cabinet_0_door_panel", [0.02, w, h], [0, w / 2, 0], [0.5, 0.55, 0.7, 1], mass=0.8)
        add_box(door, "cabinet_0_door_handle", [0.03, 0.02, 0.1], [-0.025, w - 0.05, 0], [0.2, 0.2, 0.2, 1], mass=0.05)
        door.add_site(name="cabinet_0:door_handle", pos=[-0.04, w - 0.05, 0], size=[0.01, 0, 0])
    Agent.add_suction_welds(spec, free)
    return spec, free


def build(*, with_cabinet=True, door_open=1.2, furnish: Callable[[object], list[str]] | None = None) -> DoorScene:
    """Compile the scene and put the robot at home with the door ``door_open`` rad open."""
    import mujoco

    from anomalygen.robot.agent import Agent

    spec, free = build_spec(with_cabinet=with_cabinet, furnish=furnish)
    model = spec.compile()
    data = mujoco.MjData(model)
    Agent(model).set_home(data, (0.0, 0.0, 0.0))
    if with_cabinet:
        data.joint("cabinet_0:door_hinge").qpos[0] = door_open
    mujoco.mj_forward(model, data)
    return DoorScene(model, data, free)
