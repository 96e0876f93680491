"""anomalygen: household hazard scenarios that a robot detects and resolves in simulation."""

from anomalygen.version import __version__

__all__ = ["__version__", "make_env", "make_vec_env"]

LEVELS = ("control", "skills")


def make_env(scene_dir, level: str = "control", *, judge="end", **kwargs):
    """The Gymnasium env of a built scene folder, in the referee's
    :class:`anomalygen.referee.env.JudgedEnv`.

    ``level="control"`` (default): the perception-only scene env (:mod:`anomalygen.world.env`; ``kwargs``
    go to it: ``frameskip``, ``horizon``, ``reward_fn``, ...), 7-D end-effector deltas and suction.
    ``level="skills"``: the skill-level env (:mod:`anomalygen.agents.skill_env`), one call of the
    robot's skill vocabulary per step, with the image, the textual scene description and the objects
    as its observation.

    ``judge="end"`` (the default, for outside policies; ``True`` too): when an episode ends the
    referee's verdict is in ``info["verdict"]`` and ``info["is_success"]`` (20-60 ms per episode).
    ``judge="never"`` (``False`` too; for training loops): the env's own step and info, no referee,
    unless asked with ``env.verdict_now()``."""
    from anomalygen.referee.env import JudgedEnv, judging_mode, make_judged_env

    if level == "skills":
        from anomalygen.agents.skill_env import SkillEnv

        mode = judging_mode(judge)  # a wrong mode fails before the scene loads
        return JudgedEnv(SkillEnv(scene_dir, **kwargs), scene_dir, judge=mode)
    if level != "control":
        raise ValueError(f"level is one of {', '.join(LEVELS)}, not {level!r}")
    return make_judged_env(scene_dir, judge=judge, **kwargs)


def make_vec_env(scene_dir, n_envs: int = 1, *, judge="never", subproc: bool = False, seed=None, **kwargs):
    """A Stable-Baselines3 ``VecEnv`` (what SB3's SAC, PPO, ... take) of ``n_envs`` envs of the scene,
    each as :func:`make_env` makes it: ``DummyVecEnv``, or ``SubprocVecEnv`` with ``subproc``. Made
    for training, so ``judge`` defaults to "never"; ``judge="end"`` puts the verdict in the info of
    every env whose episode ends (before SB3's automatic reset)."""
    from anomalygen.referee.env import make_judged_vec_env

    return make_judged_vec_env(scene_dir, n_envs, judge=judge, subproc=subproc, seed=seed, **kwargs)
