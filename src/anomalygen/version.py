"""The installed package version, in a module of its own so the run manifest can read it without
importing the package's top level (which offers ``make_env`` and so reaches the scene env)."""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("anomalygen")
except PackageNotFoundError:  # running from a source tree without installation
    __version__ = "0.0.0+local"
