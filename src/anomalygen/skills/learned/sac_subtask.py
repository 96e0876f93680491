"""The learned skill ``("sac", ANY)``: train SAC on a snapshot of the scene, replay on the Driver.

It runs every SAC sub-task that no family skill claims (the switch-off family has its own, with a
shipped warm start: :mod:`~anomalygen.skills.learned.part_subtask`); the sub-task's reward says what
to learn, so one skill serves every action.

1. Pre-position (``approach=True``): the 7-D action moves only the cup, never the mobile base, so a
   part out of the arm's reach could never be learned. As RoboGen does before an RL sub-task, the
   base is placed and the cup brought to the part with the same moves the push primitive makes
   (6 cm behind the part point, against the direction the joint must move; for a pull, 4 cm in
   front of it, where suction can take hold), or above the object for object sub-tasks. These
   steps run on the Driver and show in the video. Before that, a closing reward about a part that
   is already closed is moved to the open part of the same object (:func:`retarget_joints`).
2. Snapshot the Driver's full physics state and train SAC (:func:`~anomalygen.skills.learned.sac.train_sac`,
   paper settings, evaluation every ``min(steps, 1000)`` steps, stop at 90 % success) on
   :class:`~anomalygen.skills.learned.subtask_env.SubTaskEnv`, which owns copies of model and data.
3. Replay the best policy once, deterministically, on the Driver's own data from the snapshot,
   through the env's own ``control_step`` with ``drv.step`` as the physics advance (frameskip set
   to the env's 2 for the rollout), so the video hook records it and it behaves as in training.

Same seed, same result: SB3 is seeded, torch runs on CPU, the env's noise comes from its seeded
``np_random`` and MuJoCo is deterministic.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from anomalygen.schema import CLOSED_TOL, Plan, SubTask, part_labels
from anomalygen.skills.registry import ANY, Skill, SkillOutcome, register

if TYPE_CHECKING:  # pragma: no cover
    from anomalygen.skills.episode import Episode

STANDOFF = 0.06  # m behind the part point, as push_part approaches
PULL_STANDOFF = 0.04  # m in front of the part point (about 3 cm off a door face) for a pull


def snapshot(model, data) -> np.ndarray:
    """The full integration state (qpos, qvel, ctrl, mocap pose, active welds, warm start, ...)."""
    import mujoco

    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    out = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, out, spec)
    return out


def restore(model, data, state: np.ndarray) -> None:
    import mujoco

    mujoco.mj_setState(model, data, state, mujoco.mjtState.mjSTATE_INTEGRATION)
    mujoco.mj_forward(model, data)


def retarget_joints(ep: Episode, st: SubTask) -> tuple[SubTask, str]:
    """Point a closing joint term at the part that is open now, as ``scripted.joints.drive_joints`` does.

    The planner names an object's first joint, but a fridge has a freezer and a main door and either
    may be the open one; a reward about the closed freezer can never be improved on. A term whose
    target is its joint's closed value and whose joint is already closed moves to the most open joint
    of the same object whose label the step's predicates (or ``part`` param) name.
    """
    drv = ep.driver
    if st.reward is None:
        return st, ""
    labels = {str(st.params["part"])} if st.params.get("part") else set()
    for call in st.success.predicates:
        if "label" in call.args:
            labels |= set(part_labels.alternatives(str(call.args["label"])))

    def gap(js) -> float:
        return js.open_fraction_at(float(drv.data.joint(js.name).qpos[0]))

    terms, notes = [], []
    for t in st.reward.terms:
        name = t.joint or t.a
        owner = next((o for o in ep.spec.objects if any(j.name == name for j in o.joint_states)), None) \
            if t.kind == "joint" else None
        js = next((j for j in owner.joint_states if j.name == name), None) if owner else None
        if js is None or float(t.target) != js.closed_value or gap(js) > CLOSED_TOL:
            terms.append(t)
            continue
        cands = [j for j in owner.joint_states if not labels or "*" in labels or j.label in labels]
        best = max(cands, key=gap, default=None)
        if best is None or best.name == name or gap(best) <= CLOSED_TOL:
            terms.append(t)
            continue
        terms.append(t.model_copy(update={"joint": best.name, "a": None, "target": best.closed_value}))
        notes.append(f"reward moved from {name} (already closed) to {best.name}")
    if not notes:
        return st, ""
    return st.model_copy(update={"reward": st.reward.model_copy(update={"terms": terms})}), "; ".join(notes)


def pre_position(ep: Episode, st: SubTask, plan: Plan, readout) -> str:
    """Bring base and cup to where the sub-task's contact happens; returns a note for the detail."""
    from anomalygen.skills import geometry as G

    drv = ep.driver
    joint_terms = [t for t in (st.reward.terms if st.reward else []) if t.kind == "joint"]
    if joint_terms:
        t = joint_terms[0]
        joint = readout.resolved(t.joint or t.a)
        goal = float(t.target)
        q = float(drv.data.joint(joint).qpos[0])
        if abs(q - goal) <= readout.joint_tol[joint]:
            return f"{joint} already at its goal"
        body, local = G.part_point_local(ep, joint)

        def h() -> np.ndarray:
            return drv.data.xpos[body] + drv.data.xmat[body].reshape(3, 3) @ local

        sign = -1.0 if goal < q else 1.0
        # push from behind the motion; a pull (open) starts in front of the face, where suction can
        # hold it: behind a closed door is inside the cabinet
        pull = st.primitive in ("pull", "open_joint")
        side = (1.0 if pull else -1.0) * sign * G.joint_motion_direction(drv.model, drv.data, joint, h())
        if not (drv.place_base_near(h(), side=side) or drv.place_base_near(h())):
            return f"no collision-free base pose near {joint}"
        off = PULL_STANDOFF if pull else STANDOFF
        for extra in (0.15, 0.0):
            v = (1.0 if pull else -1.0) * sign * G.joint_motion_direction(drv.model, drv.data, joint, h())
            ok = drv.goto(h() + (off + extra) * v, max_steps=200, tol=0.02)
        where = "in front of" if pull else "behind"
        return f"cup {'placed' if ok else 'not quite placed'} {off * 100:.0f} cm {where} the part of {joint}"
    obj = st.params.get("object")
    if isinstance(obj, str) and obj and drv.held != obj:
        obj = plan.bindings.get(obj, obj) if obj.startswith("$") else obj
        from anomalygen.skills.scripted.primitives import approach

        return approach(ep, obj).detail
    return "no pre-positioning"


def run_sac_subtask(ep: Episode, st: SubTask, plan: Plan, *, steps: int, seed: int, threads: int = 1,
                    eval_every: int | None = None, eval_episodes: int = 5, learning_starts: int = 500,
                    approach: bool = True, log=None, reward_mode: str = "spec", n_envs: int = 1) -> SkillOutcome:
    """Train SAC for ``st`` from the Driver's current state and execute the best policy on the Driver.

    ``reward_mode="code"`` (``learn.reward_mode``) trains on reward code run in the sandbox: the
    sub-task's own code when its RewardSpec has mode "code", else its terms rendered as code
    (``reward.spec_to_code``, the same values).

    ``n_envs`` (``learn.n_envs``) envs collect experience at once (SB3 ``DummyVecEnv``).

    ``result.steps`` counts the Driver's control steps (pre-positioning plus the rollout); the
    detail says the training budget, best evaluation success and what the rollout did.
    """
    from anomalygen.skills.learned.sac import train_sac
    from anomalygen.skills.learned.subtask_env import (
        FRAMESKIP,
        HORIZON,
        SubTaskReadout,
        control_step,
        make_subtask_env,
    )

    drv = ep.driver
    if steps <= 0:
        return SkillOutcome(False, 0, "not executed: sac_steps is 0")
    s0 = drv.steps
    st, moved = retarget_joints(ep, st)
    if reward_mode == "code" and st.reward is not None and st.reward.mode == "spec" and st.reward.terms:
        from anomalygen.skills.learned.reward import spec_to_code

        st = st.model_copy(update={"reward": st.reward.model_copy(update={"mode": "code", "code": spec_to_code(st.reward)})})
    try:
        readout = SubTaskReadout(drv.model, ep.spec, st, plan.bindings)
    except ValueError as exc:
        return SkillOutcome(False, 0, f"not executed: {exc}")
    pre = pre_position(ep, st, plan, readout) if approach else "no pre-positioning"
    snap = snapshot(drv.model, drv.data)

    def make_env():
        return make_subtask_env(drv.model, snap, ep.spec, st, plan.bindings)

    policy, res = train_sac(make_env, steps, seed=seed, eval_every=eval_every or min(steps, 1000),
                            eval_episodes=eval_episodes, learning_starts=learning_starts, threads=threads,
                            stop_at=0.9, log=log, n_envs=n_envs)

    restore(drv.model, drv.data, snap)
    ee0 = drv.data.site_xpos[readout.agent.cup_site].copy()
    state = readout.state(drv.model, drv.data)
    fs, drv.frameskip = drv.frameskip, FRAMESKIP
    ok, why, t = False, "", 0
    try:
        while t < HORIZON and not ok:
            act, _ = policy.predict(readout.observation(state, ee0, t, HORIZON), deterministic=True)
            t += 1
            state, _, ok, why = control_step(readout, drv.model, drv.data, act, t, drv.step)
    finally:
        drv.frameskip = fs
        readout.close()
    joints = readout.joint_summary(state)
    detail = (("" if not moved else moved + "; ") + f"{pre}; SAC {res.steps} steps: best eval success {res.best_success:.2f} at {res.best_step} steps; "
              f"rollout {'succeeded' if ok else 'failed'} in {t} steps"
              + (f" ({joints})" if joints else "") + (f"; {why}" if why else ""))
    return SkillOutcome(ok, drv.steps - s0, detail)


@register("sac", ANY)
class LearnedSkill(Skill):
    """SAC on the sub-task's own reward, trained on the spot (``learn.sac_steps``) and replayed."""

    def run(self, episode: Episode, subtask: SubTask) -> SkillOutcome:
        cfg = episode.learning
        return run_sac_subtask(episode, subtask, episode.plan, steps=cfg.sac_steps, seed=episode.seed,
                               reward_mode=cfg.reward_mode, n_envs=cfg.n_envs)
