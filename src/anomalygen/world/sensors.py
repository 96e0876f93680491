"""Observation sensors compiled into every scene, so the env's observation costs one copy per step.

MuJoCo evaluates sensors in C inside ``mj_step``; reading ``data.sensordata`` replaces a dozen numpy
gathers per step in Python, which is what keeps the Gymnasium env's step overhead near raw physics.
Sensor names are ``obs:<group>:<item>``; groups appear in ``GROUPS`` order, so the env can slice the
vector by group. Every object of the scene has its sensors, in name order: a list of only the task's
objects would tell the robot which ones matter. Sensors are computed at the start of the last physics substep, i.e. they lag the
returned state by one timestep (2 ms).
"""

from __future__ import annotations

from anomalygen.robot.agent import Agent

GROUPS = ("robot_qpos", "robot_qvel", "ee_pos", "ee_quat", "object_pos", "object_quat", "object_joints")


def add_observation_sensors(
    spec, robot_joints: list[str], objects: list[str], object_joints: list[str]
) -> None:
    import mujoco

    S, Obj = mujoco.mjtSensor, mujoco.mjtObj

    def add(group, item, stype, objtype, objname):
        s = spec.add_sensor(name=f"obs:{group}:{item}", type=stype, objtype=objtype, objname=objname)
        return s

    for j in robot_joints:
        add("robot_qpos", j, S.mjSENS_JOINTPOS, Obj.mjOBJ_JOINT, j)
    for j in robot_joints:
        add("robot_qvel", j, S.mjSENS_JOINTVEL, Obj.mjOBJ_JOINT, j)
    add("ee_pos", Agent.EE_SITE, S.mjSENS_FRAMEPOS, Obj.mjOBJ_SITE, Agent.EE_SITE)
    add("ee_quat", Agent.EE_SITE, S.mjSENS_FRAMEQUAT, Obj.mjOBJ_XBODY, Agent.CUP_BODY)
    for o in objects:
        add("object_pos", o, S.mjSENS_FRAMEPOS, Obj.mjOBJ_XBODY, o)
    for o in objects:
        add("object_quat", o, S.mjSENS_FRAMEQUAT, Obj.mjOBJ_XBODY, o)
    for j in object_joints:
        add("object_joints", j, S.mjSENS_JOINTPOS, Obj.mjOBJ_JOINT, j)


def sensor_items(model, group: str) -> list[str]:
    """The items (joint or body names) of one sensor group, in the order they appear in the vector."""
    import mujoco

    prefix = f"obs:{group}:"
    names = (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SENSOR, i) or "" for i in range(model.nsensor))
    return [n[len(prefix):] for n in names if n.startswith(prefix)]


def sensor_layout(model) -> dict[str, slice]:
    """Group -> slice of ``data.sensordata`` (empty dict when the scene has no observation sensors)."""
    import mujoco

    spans: dict[str, list[int]] = {}
    for i in range(model.nsensor):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SENSOR, i) or ""
        if not name.startswith("obs:"):
            continue
        group = name.split(":")[1]
        adr, dim = int(model.sensor_adr[i]), int(model.sensor_dim[i])
        lo, hi = spans.get(group, [adr, adr])
        spans[group] = [min(lo, adr), max(hi, adr + dim)]
    return {g: slice(*spans[g]) for g in GROUPS if g in spans}
