"""How deep into an opened compartment the suction cup gets without the arm touching anything.

Why: ``take_out_of`` fails on t0044 (a milk carton on a fridge's floor, its front face 0.40 m behind
the opening, under a shelf whose front edge is 0.39 m up). This measures whether any arm pose could
do better than the skill: the task's plan is run up to its ``take_out_of`` step (the fridge opened
and its compartment measured, as the robot perceives it), then, for cup poses at the object's
height with the cup's axis pointing in through the opening (level, or tilted 20 degrees down or up),
base poses just outside the opening (across its width, turned by up to 0.3 rad) and random IK
restarts, it bisects for the deepest cup position with a collision-free arm and base. The object's
face toward the opening is where the cup has to be (minus the suction range).

``--drop`` lowers the arm's mount below the lowest torso lift (not a skill: a robot change), to see
what it would take.

    PYTHONPATH=src .venv/bin/python benchmarks/reach_into_compartment.py --run RUN --task TASK [--drop 0.1]
"""

from __future__ import annotations

import argparse
import json

import numpy as np


def _free_pose(drv, cup, axis, mouth_base, lateral, rng, restarts: int) -> bool:
    """A collision-free arm (and base) with the cup face at ``cup``, its axis along ``axis``?"""
    import mujoco

    from anomalygen.robot.agent import Agent
    from anomalygen.robot.arm_motion import _checker, _reference_state
    from anomalygen.robot.ik import quat_z_to, solve_ik

    m, d = drv.model, drv.data
    lim = m.jnt_range[[m.joint(n).id for n in Agent.ARM_JOINTS]]
    for off in lateral:
        for dyaw in (0.0, -0.3, 0.3):
            b = mouth_base + off
            yaw = float(np.arctan2(cup[1] - b[1], cup[0] - b[0])) + dyaw
            for n, v in zip(Agent.BASE_JOINTS, (b[0], b[1], yaw), strict=True):
                d.actuator(n).ctrl[0] = d.joint(n).qpos[0] = v
            mujoco.mj_kinematics(m, d)
            ref = _reference_state(m, d)
            chk = _checker(m, ref, None, None, 0.0, ())
            for k in range(restarts):
                q0 = np.asarray(Agent.HOME_ARM) if k == 0 else rng.uniform(lim[:, 0], lim[:, 1])
                r = solve_ik(m, ref, Agent.CUP_SITE, Agent.ARM_JOINTS, cup, quat_z_to(axis), q_init=q0, iterations=150)
                if r.success and chk.valid(r.qpos[chk.qadr]):
                    return True
    return False


def main() -> None:
    import mujoco

    from anomalygen.rng import item_rng
    from anomalygen.robot.agent import Agent
    from anomalygen.schema import Plan
    from anomalygen.skills.catalogue import skill_for
    from anomalygen.skills.episode import Episode
    from anomalygen.world.graph import load_scene
    from anomalygen.world.perception import perceived_spec

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--run", required=True)
    ap.add_argument("--task", required=True)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--drop", type=float, default=0.0, help="m the arm's mount is lowered below lift 0")
    ap.add_argument("--restarts", type=int, default=10)
    a = ap.parse_args()
    plan = Plan.model_validate_json(open(f"{a.run}/plans/{a.task}.json").read())
    model, data, spec = load_scene(f"{a.run}/scenes/{a.task}")
    ep = Episode(model, data, perceived_spec(spec), rng=item_rng(a.seed, a.task), plan=plan)
    drv = ep.driver
    step = next(st for st in plan.subtasks if st.primitive == "take_out_of")
    for st in plan.subtasks[:plan.subtasks.index(step)]:
        skill_for(ep, st)().run(ep, st)
        drv.settle(10)
    obj, container = step.params["object"], step.params["region"]
    lo, hi, out = ep.memory.compartments[container]
    k = int(np.argmax(np.abs(out[:2])))
    mouth = hi[k] if out[k] > 0 else lo[k]
    olo, ohi = drv.aabb(obj)
    face = ohi[k] if out[k] > 0 else olo[k]
    need = abs(face - mouth) - Agent.SUCTION_RANGE  # cup depth behind the opening that touches the face
    side = np.zeros(3)
    side[1 - k] = 1.0
    centre = (olo + ohi) / 2
    width = hi[1 - k] - lo[1 - k]
    lateral = [side * s * width / 2 for s in (0.0, -0.6, 0.6)]
    # the base's rim just outside the opening, in line with the object
    mouth_base = centre.copy()
    mouth_base[k] = mouth + out[k] * (Agent.BASE_RADIUS + 0.03)
    model.body(Agent.TORSO).pos[2] = -a.drop
    rng = np.random.default_rng(a.seed)
    inward = -out / np.linalg.norm(out)
    heights = np.linspace(olo[2] + 0.03, ohi[2] - 0.03, 3)

    def reachable(depth: float) -> bool:
        for z in heights:
            for tilt in (0.0, -20.0, 20.0):  # cup axis pitched down / up from level
                t = np.radians(tilt)
                axis = inward * np.cos(t) + np.array([0, 0, np.sin(t)])
                cup = centre.copy()
                cup[k] = mouth - out[k] * depth
                cup[2] = z
                if _free_pose(drv, cup, axis, mouth_base, lateral, rng, a.restarts):
                    return True
        return False

    ok, bad = 0.0, need
    if reachable(need):
        ok = need
    else:
        for _ in range(6):
            mid = (ok + bad) / 2
            ok, bad = (mid, bad) if reachable(mid) else (ok, mid)
    mujoco.mj_forward(model, data)
    print(json.dumps({"task": a.task, "object": obj, "container": container, "drop_m": a.drop,
                      "face_depth_m": round(float(abs(face - mouth)), 3),
                      "object_z_m": [round(float(olo[2]), 3), round(float(ohi[2]), 3)],
                      "deepest_free_cup_depth_m": round(float(ok), 3),
                      "short_by_m": round(float(need - ok), 3)}))


if __name__ == "__main__":
    main()
