"""anomalygen: household hazard scenarios that a robot detects and resolves in simulation."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("anomalygen")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0.0.0+local"

__all__ = ["__version__", "make_env"]


def make_env(scene_dir, **kwargs):
    """Create the Gymnasium env for a built scene folder (see :mod:`anomalygen.scene.env`)."""
    from anomalygen.scene.env import make_env as _make_env

    return _make_env(scene_dir, **kwargs)
