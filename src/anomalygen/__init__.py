"""anomalygen: household hazard scenarios that a robot detects and resolves in simulation."""

from anomalygen.version import __version__

__all__ = ["__version__", "make_env"]

LEVELS = ("control", "skills")


def make_env(scene_dir, level: str = "control", **kwargs):
    """The Gymnasium env of a built scene folder, judged: the referee's
    :class:`anomalygen.referee.env.JudgedEnv` puts its verdict in ``info["verdict"]`` (and
    ``info["is_success"]``) when an episode ends.

    ``level="control"`` (default): the perception-only scene env (:mod:`anomalygen.world.env`), 7-D
    end-effector deltas and suction. ``level="skills"``: the skill-level env
    (:mod:`anomalygen.agents.skill_env`), one call of the robot's skill vocabulary per step, with the
    image, the textual scene description and the objects as its observation."""
    from anomalygen.referee.env import JudgedEnv

    if level == "skills":
        from anomalygen.agents.skill_env import SkillEnv

        return JudgedEnv(SkillEnv(scene_dir, **kwargs), scene_dir)
    if level != "control":
        raise ValueError(f"level is one of {', '.join(LEVELS)}, not {level!r}")
    from anomalygen.world.env import make_env as _make_env

    return JudgedEnv(_make_env(scene_dir, **kwargs), scene_dir)
