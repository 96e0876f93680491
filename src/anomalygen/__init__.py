"""anomalygen: household hazard scenarios that a robot detects and resolves in simulation."""

from anomalygen.version import __version__

__all__ = ["__version__", "make_env"]


def make_env(scene_dir, **kwargs):
    """The Gymnasium env of a built scene folder, judged: the perception-only scene env
    (:mod:`anomalygen.world.env`) wrapped in :class:`anomalygen.referee.env.JudgedEnv`, which puts the
    referee's verdict in ``info["verdict"]`` (and ``info["is_success"]``) when an episode ends."""
    from anomalygen.referee.env import JudgedEnv
    from anomalygen.world.env import make_env as _make_env

    return JudgedEnv(_make_env(scene_dir, **kwargs), scene_dir)
