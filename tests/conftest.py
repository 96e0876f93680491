"""Test-wide environment: offline models, headless rendering, temp folders for tools that write $HOME."""

import os
import tempfile

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
os.environ.setdefault("TOKENIZERS_PARALLELISM", "false")
os.environ.setdefault("RAY_AUTH_MODE", "disabled")
os.environ.setdefault("MPLCONFIGDIR", tempfile.mkdtemp(prefix="mpl-"))
# Tests must not read a developer's own configuration.
for key in [k for k in os.environ if k.startswith("ANOMALYGEN_")]:
    del os.environ[key]


import pytest  # noqa: E402


@pytest.hookimpl(tryfirst=True)  # before xdist reads the groups in its own hook
def pytest_collection_modifyitems(items):
    """Tests on the real GGUF share one xdist worker (``--dist loadgroup``): two llama.cpp servers,
    each spinning two threads on a two-core machine, starve each other and the physics tests."""
    for item in items:
        if item.get_closest_marker("gguf") and not item.get_closest_marker("xdist_group"):
            item.add_marker(pytest.mark.xdist_group("gguf"))
