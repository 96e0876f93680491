"""Inverse kinematics by damped least squares on MuJoCo's site Jacobians.

Why DLS: it stays well behaved near singularities (the arm stretched towards the floor is one) where
a pseudo-inverse explodes, and one iteration is cheap enough to run inside every control step of the
RL env. Works on any subset of joints (the 7 arm joints, optionally the mobile base too), honours
joint limits by clipping, and never touches the caller's ``MjData`` unless asked to.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class IKResult:
    qpos: np.ndarray  # full model qpos with the solution written into the chosen joints
    pos_error: float
    rot_error: float
    success: bool
    iterations: int


def joint_dofs(model, joint_names) -> tuple[np.ndarray, np.ndarray]:
    """qpos and dof addresses of 1-dof joints (hinge/slide)."""
    import mujoco

    qadr, dadr = [], []
    for name in joint_names:
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if j < 0:
            raise KeyError(f"no joint {name!r}")
        qadr.append(model.jnt_qposadr[j])
        dadr.append(model.jnt_dofadr[j])
    return np.asarray(qadr), np.asarray(dadr)


def orientation_error(current_quat: np.ndarray, target_quat: np.ndarray) -> np.ndarray:
    """Axis-angle (world frame) rotating ``current`` onto ``target``."""
    import mujoco

    neg = np.zeros(4)
    mujoco.mju_negQuat(neg, current_quat)
    diff = np.zeros(4)
    mujoco.mju_mulQuat(diff, target_quat, neg)
    if diff[0] < 0:
        diff = -diff
    err = np.zeros(3)
    mujoco.mju_quat2Vel(err, diff, 1.0)
    return err


def site_pose(model, data, site: str) -> tuple[np.ndarray, np.ndarray]:
    import mujoco

    sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, site)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, data.site_xmat[sid])
    return data.site_xpos[sid].copy(), quat


def ik_step(model, data, site: str, qadr, dadr, target_pos, target_quat=None, *, damping=0.05, max_step=0.2,
            rot_weight=0.5) -> np.ndarray:
    """One DLS update of the chosen joints (returns the new joint values; ``data`` is not changed).

    ``data`` must have current kinematics (``mj_kinematics`` + ``mj_comPos``, or ``mj_forward``).
    """
    import mujoco

    sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, site)
    jacp = np.zeros((3, model.nv))
    jacr = np.zeros((3, model.nv))
    mujoco.mj_jacSite(model, data, jacp, jacr, sid)
    err = np.asarray(target_pos, dtype=float) - data.site_xpos[sid]
    rows = [jacp[:, dadr]]
    errs = [err]
    if target_quat is not None:
        _, quat = site_pose(model, data, site)
        rows.append(rot_weight * jacr[:, dadr])
        errs.append(rot_weight * orientation_error(quat, np.asarray(target_quat, dtype=float)))
    jac = np.vstack(rows)
    e = np.concatenate(errs)
    dq = jac.T @ np.linalg.solve(jac @ jac.T + damping**2 * np.eye(jac.shape[0]), e)
    norm = np.linalg.norm(dq)
    if norm > max_step:
        dq *= max_step / norm
    q = data.qpos[qadr] + dq
    lo = np.array([model.jnt_range[model.dof_jntid[d]][0] for d in dadr])
    hi = np.array([model.jnt_range[model.dof_jntid[d]][1] for d in dadr])
    limited = np.array([model.jnt_limited[model.dof_jntid[d]] for d in dadr], dtype=bool)
    q[limited] = np.clip(q[limited], lo[limited], hi[limited])
    return q


def solve_ik(model, data, site: str, joint_names, target_pos, target_quat=None, *, iterations=300, tol_pos=0.004,
             tol_rot=0.05, damping=0.05, q_init=None, rng: np.random.Generator | None = None, restarts=0) -> IKResult:
    """Iterate DLS on a scratch copy of ``data`` until the site reaches the target pose.

    With ``restarts`` and ``rng``, failed attempts restart from random joint values inside limits
    (the first attempt starts from ``q_init`` or the current configuration).
    """
    import mujoco

    qadr, dadr = joint_dofs(model, joint_names)
    scratch = mujoco.MjData(model)
    best: IKResult | None = None
    for attempt in range(restarts + 1):
        scratch.qpos[:] = data.qpos
        if attempt == 0 and q_init is not None:
            scratch.qpos[qadr] = q_init
        elif attempt > 0 and rng is not None:
            for a, d in zip(qadr, dadr, strict=True):
                j = model.dof_jntid[d]
                if model.jnt_limited[j]:
                    lo, hi = model.jnt_range[j]
                    scratch.qpos[a] = rng.uniform(lo, hi) if rng is not None else scratch.qpos[a]
        pe = re = np.inf
        for it in range(iterations):
            mujoco.mj_kinematics(model, scratch)
            mujoco.mj_comPos(model, scratch)  # the Jacobian needs com-based quantities
            pos, quat = site_pose(model, scratch, site)
            pe = float(np.linalg.norm(np.asarray(target_pos) - pos))
            re = 0.0 if target_quat is None else float(np.linalg.norm(orientation_error(quat, np.asarray(target_quat))))
            if pe < tol_pos and re < tol_rot:
                return IKResult(scratch.qpos.copy(), pe, re, True, it)
            scratch.qpos[qadr] = ik_step(model, scratch, site, qadr, dadr, target_pos, target_quat, damping=damping)
        res = IKResult(scratch.qpos.copy(), pe, re, False, iterations)
        if best is None or pe + 0.1 * re < best.pos_error + 0.1 * best.rot_error:
            best = res
    assert best is not None
    return best


def quat_z_to(direction: np.ndarray, roll_ref: np.ndarray | None = None) -> np.ndarray:
    """A quaternion whose z axis points along ``direction`` (the cup's approach axis)."""
    import mujoco

    z = np.asarray(direction, dtype=float)
    z = z / np.linalg.norm(z)
    ref = np.array([1.0, 0.0, 0.0]) if roll_ref is None else np.asarray(roll_ref, dtype=float)
    if abs(np.dot(ref, z)) > 0.95:
        ref = np.array([0.0, 1.0, 0.0])
    x = ref - np.dot(ref, z) * z
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, np.column_stack([x, y, z]).ravel())
    return quat
