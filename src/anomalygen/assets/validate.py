"""Physical validation of an asset: compiles, rests still on a floor, every joint moves through its
whole range, and a thumbnail renders.

Why each check: scenes fail in confusing ways when an asset explodes on contact, slides away, or has a
door that jams on its own cabinet; finding that here, per asset, is far cheaper than in a scene.
Joints are driven by stiff position servos one after another (so a rack can leave once its door is
open), held open, then closed again in reverse order.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from anomalygen.schema import ValidationCheck, ValidationReport

if TYPE_CHECKING:
    from anomalygen.assets.model import Asset

REST_SECONDS = 2.0
MAX_DRIFT = 0.01  # metres
MAX_TILT = 0.1  # radians
REACH_TOL = 0.06  # fraction of a joint's span


class ValidationResult(ValidationReport):
    asset_id: str = ""
    category: str = ""


def _finite(data) -> bool:
    return bool(np.all(np.isfinite(data.qpos)) and np.all(np.isfinite(data.qvel)))


def check_rest(asset: Asset) -> ValidationCheck:
    """Drop the asset (joints at their zero pose) 0.5 mm onto a floor, simulate 2 s, measure drift/tilt."""
    import mujoco

    from anomalygen.assets.render import showcase_spec

    spec, _ = showcase_spec(asset, free=True)
    model = spec.compile()
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    bid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "holder")
    p0, q0 = data.xpos[bid].copy(), data.xquat[bid].copy()
    steps = int(REST_SECONDS / model.opt.timestep)
    for _ in range(steps):
        mujoco.mj_step(model, data)
    if not _finite(data):
        return ValidationCheck(name="rest", passed=False, detail="NaN in the state")
    drift = float(np.linalg.norm(data.xpos[bid] - p0))
    dq = abs(float(np.dot(data.xquat[bid], q0)))
    tilt = 2 * math.acos(min(1.0, dq))
    ok = drift <= MAX_DRIFT and tilt <= MAX_TILT
    return ValidationCheck(
        name="rest",
        passed=ok,
        value=round(drift, 5),
        limit=MAX_DRIFT,
        detail=f"drift {drift * 1000:.1f} mm, tilt {tilt:.3f} rad after {REST_SECONDS:.0f} s",
    )


def _gravity_load(model, data, jid: int) -> float:
    """Weight of the subtree a joint moves times its lever arm (or the weight, for a slide)."""
    import mujoco

    body = model.jnt_bodyid[jid]
    m = float(model.body_subtreemass[body])
    if model.jnt_type[jid] == mujoco.mjtJoint.mjJNT_SLIDE:
        return m * 9.81
    axis = data.xaxis[jid]
    r = data.subtree_com[body] - data.xanchor[jid]
    return m * 9.81 * float(np.linalg.norm(np.cross(axis, r)))


def check_joints(asset: Asset, *, ramp_s: float = 0.5, hold_s: float = 0.25) -> list[ValidationCheck]:
    """Drive every joint to its far end and back with a stiff servo; report reach, lock-up, explosion."""
    import mujoco

    from anomalygen.assets.render import showcase_spec

    if not asset.joints:
        return []
    # Lifted clear of the floor: this checks the mechanism itself (floor friction on a fixed
    # asset's wheels or buttons is a scene matter, not an asset defect).
    spec, _ = showcase_spec(asset, free=False, lift=0.005 + 0.01 * asset.size)
    spec.option.timestep = 0.001
    model0 = spec.compile()
    data0 = mujoco.MjData(model0)
    mujoco.mj_forward(model0, data0)

    def inertia_of(dof: int) -> float:
        e, out = np.zeros(model0.nv), np.zeros(model0.nv)
        e[dof] = 1.0
        mujoco.mj_mulM(model0, data0, out, e)
        return float(out[dof])

    names = ["a_" + j.name for j in asset.joints]
    for j, name in zip(asset.joints, names, strict=True):
        jid = mujoco.mj_name2id(model0, mujoco.mjtObj.mjOBJ_JOINT, name)
        dof = model0.jnt_dofadr[jid]
        span = abs(j.range[1] - j.range[0])
        inertia = inertia_of(dof)
        stiff = float(np.atleast_1d(model0.jnt_stiffness[jid])[0])
        resist = stiff * 2 * span + float(model0.dof_frictionloss[dof]) + _gravity_load(model0, data0, jid)
        kp = max(inertia * (2 * math.pi * 6) ** 2, resist / (0.01 * span))
        kp = min(kp, inertia * (2 * math.pi * 150) ** 2)  # keep the servo stable at dt = 1 ms (omega*dt < 1)
        kv = 2 * math.sqrt(kp * inertia)
        act = spec.add_actuator(name=f"servo_{j.name}", target=name, trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_position(kp=kp, kv=kv)
    model = spec.compile()
    data = mujoco.MjData(model)
    qadr = [model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n)] for n in names]
    for k, j in enumerate(asset.joints):
        data.qpos[qadr[k]] = j.closed_value
        data.ctrl[k] = j.closed_value
    mujoco.mj_forward(model, data)
    far = [
        j.range[1] if abs(j.range[1] - j.closed_value) >= abs(j.range[0] - j.closed_value) else j.range[0]
        for j in asset.joints
    ]
    reached = [[False, False] for _ in asset.joints]
    final = [[None, None] for _ in asset.joints]
    worst_speed = 0.0
    exploded = None

    def move(k: int, start: float, goal: float, phase: int) -> None:
        nonlocal worst_speed, exploded
        n_ramp, n_hold = int(ramp_s / model.opt.timestep), int(hold_s / model.opt.timestep)
        for i in range(n_ramp + n_hold):
            data.ctrl[k] = start + (goal - start) * min(1.0, (i + 1) / n_ramp)
            mujoco.mj_step(model, data)
            if not _finite(data):
                exploded = asset.joints[k].name
                return
        worst_speed = max(worst_speed, float(np.max(np.abs(data.qvel))) if model.nv else 0.0)
        span = abs(far[k] - asset.joints[k].closed_value)
        reached[k][phase] = abs(data.qpos[qadr[k]] - goal) <= REACH_TOL * span + 1e-9
        final[k][phase] = round(float(data.qpos[qadr[k]]), 4)

    order = list(range(len(asset.joints)))
    for k in order:
        move(k, asset.joints[k].closed_value, far[k], 0)
        if exploded:
            break
    if not exploded:
        for k in reversed(order):
            move(k, far[k], asset.joints[k].closed_value, 1)
            if exploded:
                break
    checks = []
    for k, j in enumerate(asset.joints):
        ok = not exploded and all(reached[k])
        detail = (
            "exploded (NaN)"
            if exploded == j.name
            else ("" if ok else f"did not reach {'far end' if not reached[k][0] else 'closed'} ({final[k]})")
        )
        checks.append(
            ValidationCheck(
                name=f"joint:{j.name}",
                passed=ok,
                value=round(abs(far[k] - j.closed_value), 4),
                detail=detail or f"{j.label} {j.type} through {j.range[0]:.3f}..{j.range[1]:.3f}",
            )
        )
    checks.append(
        ValidationCheck(
            name="joint_speed",
            passed=exploded is None and worst_speed < 200.0,
            value=round(worst_speed, 3),
            limit=200.0,
            detail="largest joint speed at rest after a move",
        )
    )
    return checks


def check_render(asset: Asset) -> ValidationCheck:
    from anomalygen.assets.render import render_asset

    rgb = render_asset(asset, width=96, height=72)
    spread = float(rgb.astype(np.float32).std())
    return ValidationCheck(
        name="render",
        passed=rgb.shape == (72, 96, 3) and spread > 2.0,
        value=round(spread, 2),
        detail="thumbnail pixel spread",
    )


def validate_asset(asset: Asset, *, render: bool = True) -> ValidationResult:
    """Every check on one asset; never raises for a broken asset, reports it instead."""
    checks: list[ValidationCheck] = []
    try:
        model = asset.spec.copy().compile()
        checks.append(
            ValidationCheck(
                name="compile",
                passed=True,
                value=float(model.nbody),
                detail=f"{model.nbody} bodies, {model.njnt} joints, {model.ngeom} geoms",
            )
        )
    except Exception as exc:  # a broken asset is a result, not a crash
        checks.append(ValidationCheck(name="compile", passed=False, detail=str(exc)[:200]))
        return ValidationResult(
            ok=False,
            checks=checks,
            reason=f"compile: {exc}"[:200],
            asset_id=asset.asset_id,
            category=asset.category,
        )
    for fn in (check_rest, check_joints) + ((check_render,) if render else ()):
        try:
            out = fn(asset)
            checks.extend(out if isinstance(out, list) else [out])
        except Exception as exc:
            checks.append(
                ValidationCheck(
                    name=fn.__name__.removeprefix("check_"),
                    passed=False,
                    detail=f"{type(exc).__name__}: {exc}"[:200],
                )
            )
    failed = [c for c in checks if not c.passed]
    reason = "; ".join(f"{c.name}: {c.detail}" for c in failed)[:300]
    return ValidationResult(
        ok=not failed, checks=checks, reason=reason, asset_id=asset.asset_id, category=asset.category
    )
