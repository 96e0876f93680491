"""Fixtures for the LLM-layer tests: the scripted server factory and a config pointing at it."""

from support.fixtures import llm_config_for, scripted_server  # noqa: F401

__all__ = ["llm_config_for", "scripted_server"]
