"""The learned skill ``("sac", "switch_off")``: grasp the part, fine-tune the shipped warm start, execute.

The learn stage's path for sub-tasks of the switch-off family (``params["family"] == "switch_off"``,
planned by the knowledge planner because the KB marks the recipe step ``"method": "sac"``; or an
LLM-planned SAC step that drives a knob or switch to off: the skill claims those too, when rewards are
specs):

The sequence is the family's one (:func:`~anomalygen.skills.part_motion.hold_and_lead`, the scripted
primitive's too); what this skill adds is the policy, made once the part is held:

1. :func:`~anomalygen.skills.part_motion.grasp_part` puts the cup on the part's face and holds it (the
   approach is motion-planned, as RoboGen pre-positions before an RL sub-task).
2. The warm start (``anomalygen/data/policies/switch_off.zip``, trained over many built scenes by
   ``benchmarks/train_warm_start.py``) is evaluated on a snapshot of this scene
   (:class:`~anomalygen.skills.learned.part_env.PartTurnEnv`, 5 seeded episodes); if it does not already reach
   90 % it is fine-tuned with SAC for at most ``steps`` (capped at ``FINETUNE_MAX``) transitions, ``n_envs`` envs at once,
   keeping the best checkpoint by success.
3. The policy is replayed once, deterministically, on the Driver's own data from the snapshot
   (:func:`~anomalygen.skills.part_motion.lead_held_part`, at the env's frameskip), so the video shows it.
   The cup then lets go and backs off (:func:`~anomalygen.skills.part_motion.let_go`).

Without a shipped policy it trains from scratch within ``steps``. The caller (``learn/execute.py``)
falls back to the primitive when the replay fails, and records why.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from anomalygen.schema import Plan, SubTask
from anomalygen.skills.registry import Skill, SkillOutcome, register

if TYPE_CHECKING:  # pragma: no cover
    from anomalygen.skills.episode import Episode

FAMILY = "switch_off"
EVAL_EPISODES = 5
# Fine-tuning budget per part, at most: an oven has up to five knobs on and `make demo` runs 20 tasks
# in < 15 min on 2 cores; ~1000 steps of a 64x64 SAC take 20-40 s there (figures in docs/learn.md).
FINETUNE_MAX = 1000


def warm_start_path(family: str = FAMILY) -> Path | None:
    """The shipped policy of a family, None when the package has none."""
    p = Path(str(resources.files("anomalygen") / "data" / "policies" / f"{family}.zip"))
    return p if p.is_file() else None


def is_switch_off(ep: Episode, st: SubTask) -> bool:
    """A sub-task of the family: planned so (``params["family"]``), or, from the LLM planner, one
    that drives a knob or switch of the scene to its off value."""
    if st.params.get("family") == FAMILY:
        return True
    js = _joint_state(ep, str(st.params.get("joint", "")))
    target = st.params.get("target")
    return js is not None and js.is_switch and (
        target is None or abs(float(target) - js.closed_value) < 1e-6)


def _joint_state(ep: Episode, joint: str):
    for o in ep.spec.objects:
        for js in o.joint_states:
            if js.name == joint:
                return js
    return None


def far_value(js) -> float:
    lo, hi = js.range
    return float(hi if abs(hi - js.closed_value) >= abs(lo - js.closed_value) else lo)


def run_part_subtask(ep: Episode, st: SubTask, plan: Plan, *, steps: int, seed: int, n_envs: int = 1, threads: int = 1,
                     warm_start: Path | None | str = "shipped", log=None) -> SkillOutcome:
    """Grasp the part, fine-tune the family policy on this scene (if needed), execute it on the Driver."""
    from anomalygen.skills.learned.part_env import HORIZON, PartStart, make_part_env
    from anomalygen.skills.learned.sac import train_sac
    from anomalygen.skills.part_motion import PartReadout, hold_and_lead

    drv = ep.driver
    joint = str(st.params.get("joint", ""))
    js = _joint_state(ep, joint)
    if js is None:
        return SkillOutcome(False, 0, f"not executed: {joint!r} is no articulated part in the scene")
    closed, far = float(js.closed_value), far_value(js)
    s0 = drv.steps
    now = float(drv.data.joint(joint).qpos[0])
    if js.is_off(value=now):
        return SkillOutcome(True, 0, f"{joint} already off ({now:.3f})")
    warm = warm_start_path() if warm_start == "shipped" else (Path(warm_start) if warm_start else None)
    if warm is None and steps <= 0:
        return SkillOutcome(False, 0, "not executed: no warm start shipped and sac_steps is 0")
    tuned = ""

    def tune_on_the_hold():
        """Fine-tune on a snapshot of the hold, put the Driver back on it, and act by the best policy."""
        nonlocal tuned
        import mujoco

        kind = mujoco.mjtState.mjSTATE_INTEGRATION
        snap = np.empty(mujoco.mj_stateSize(drv.model, kind))
        mujoco.mj_getState(drv.model, drv.data, snap, kind)
        start = PartStart(drv.model, snap, ep.spec, st, plan.bindings, joint, closed, far)

        def make_env():
            return make_part_env([start])

        budget = min(steps, FINETUNE_MAX)
        eval_every = max(1, min(budget, 500)) if budget > 0 else 1
        policy, res = train_sac(make_env, max(0, budget), seed=seed, eval_every=eval_every, eval_episodes=EVAL_EPISODES,
                                learning_starts=200, threads=threads, stop_at=0.9, log=log, n_envs=n_envs,
                                net_arch=(64, 64), init_model=None if warm is None else str(warm))
        tuned = ("warm start" if warm is not None else "from scratch") + (
            f" already at {res.curve[0]['success']:.2f} on this scene, not fine-tuned" if res.steps == 0 and warm is not None
            else f", {res.steps} SAC steps: best eval success {res.best_success:.2f} at {res.best_step} steps")
        mujoco.mj_setState(drv.model, drv.data, snap, kind)
        mujoco.mj_forward(drv.model, drv.data)
        return lambda obs: policy.predict(obs, deterministic=True)[0]

    lead = hold_and_lead(ep, PartReadout(drv.model, joint, closed, far), tune_on_the_hold, horizon=HORIZON)
    if not lead.held:
        return SkillOutcome(False, drv.steps - s0, f"not executed: {lead.why}")
    q, t = lead.led_to, lead.steps
    after = float(drv.data.joint(joint).qpos[0])
    ok = lead.off and js.is_off(value=after)
    detail = (f"{lead.why}; {tuned}; rollout {'turned' if ok else 'did not turn'} {joint} to off in {t} steps "
              f"({q:.3f}, off {closed:.3f}, on {far:.3f})" + (f" ({lead.stopped})" if lead.stopped else "")
              + (f"; {after:.3f} after letting go" if abs(after - q) > 1e-3 else ""))
    return SkillOutcome(ok, drv.steps - s0, detail)


@register("sac", FAMILY)
class SwitchOffSkill(Skill):
    """The switch-off family: warm start, fine-tuning on the scene, replay (see the module docstring)."""

    @classmethod
    def claims(cls, episode: Episode, subtask: SubTask) -> bool:
        # reward code (learn.reward_mode "code") is learned from scratch by the generic SAC skill
        return episode.learning.reward_mode == "spec" and is_switch_off(episode, subtask)

    def run(self, episode: Episode, subtask: SubTask) -> SkillOutcome:
        return run_part_subtask(episode, subtask, episode.plan, steps=episode.learning.sac_steps,
                                seed=episode.seed, n_envs=episode.learning.n_envs)
