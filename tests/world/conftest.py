"""The scenes the builder's tests build once per session, read here as a built world."""

from scene.conftest import built_scenes, scene_settings  # noqa: F401
