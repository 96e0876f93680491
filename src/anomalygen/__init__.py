"""anomalygen: household hazard scenarios that a robot detects and resolves in simulation."""

from anomalygen.version import __version__

__all__ = ["__version__", "make_env"]


def make_env(scene_dir, **kwargs):
    """Create the Gymnasium env for a built scene folder (see :mod:`anomalygen.scene.env`)."""
    from anomalygen.scene.env import make_env as _make_env

    return _make_env(scene_dir, **kwargs)
