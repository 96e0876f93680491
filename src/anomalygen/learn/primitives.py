"""Action primitives driven through the end-effector mocap target (the ``ee_track`` weld).

Implemented so far: :func:`push_joint`, the push/pull primitive for hinged and sliding parts (doors,
drawers, lids). It needs no learned policy: the part's kinematics say where to push. A point ``h`` on
a part hinged about axis ``a`` through ``p`` moves along ``a x (h - p)`` when the joint value grows,
so the cup first goes to a pre-contact point 0.05 m on the far side of that direction (behind the
motion), then follows the moving contact point while the joint tracks the goal. A slide joint moves
along its axis. Contact is kept by re-aiming at the part point every step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class PrimitiveResult:
    success: bool
    steps: int
    detail: str = ""


def _step(env_like, target_pos) -> None:
    """Move the mocap target towards ``target_pos`` at most ``dp`` per control step, then simulate."""
    import mujoco

    m, d = env_like.model, env_like.data
    mid = env_like._mocap
    cup = d.xpos[env_like._cup]
    delta = np.asarray(target_pos) - d.mocap_pos[mid]
    n = np.linalg.norm(delta)
    if n > env_like.dp:
        delta *= env_like.dp / n
    d.mocap_pos[mid] = cup + np.clip(d.mocap_pos[mid] + delta - cup, -0.08, 0.08)
    for _ in range(env_like.frameskip):
        mujoco.mj_step(m, d)


def joint_motion_direction(model, data, joint: str, point: np.ndarray) -> np.ndarray:
    """Unit world direction in which ``point`` (on the part) moves when the joint value increases."""
    import mujoco

    j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, joint)
    axis = data.xaxis[j]
    if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_SLIDE:
        return axis / np.linalg.norm(axis)
    v = np.cross(axis, np.asarray(point) - data.xanchor[j])
    return v / (np.linalg.norm(v) + 1e-12)


def push_joint(env_like, joint: str, goal: float, point_site: str, *, tol: float = 0.08, max_steps: int = 300,
               standoff: float = 0.05, on_step=None) -> PrimitiveResult:
    """Drive ``joint`` to ``goal`` by pushing at the part point ``point_site`` (door handle, drawer front)."""
    import mujoco

    m, d = env_like.model, env_like.data
    sid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, point_site)
    steps = 0

    def q() -> float:
        return float(d.joint(joint).qpos[0])

    sign = -1.0 if goal < q() else 1.0  # push against or along the opening direction
    # 1. approach: to the pre-contact point behind the motion, with a lateral stand-off first
    for phase in ("clear", "precontact"):
        for _ in range(max_steps // 3):
            h = d.site_xpos[sid]
            v = sign * joint_motion_direction(m, d, joint, h)
            pre = h - standoff * v + (np.array([0, 0, 0.0]) if phase == "precontact" else -0.15 * v)
            _step(env_like, pre)
            steps += 1
            if on_step:
                on_step()
            if np.linalg.norm(d.site_xpos[env_like._site_ee] - pre) < 0.02:
                break
    # 2. push: follow the moving point, aiming past it along the motion
    while steps < max_steps and abs(q() - goal) > tol and sign * (goal - q()) > 0:
        h = d.site_xpos[sid]
        v = sign * joint_motion_direction(m, d, joint, h)
        _step(env_like, h + 0.06 * v)
        steps += 1
        if on_step:
            on_step()
    ok = abs(q() - goal) <= tol or sign * (goal - q()) <= 0
    return PrimitiveResult(ok, steps, f"{joint} = {q():.3f} (goal {goal:.3f})")
