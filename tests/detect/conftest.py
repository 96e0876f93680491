"""Fixtures for detection tests: the knowledge base and task proposals to judge against."""

from __future__ import annotations

import pytest

from support.fixtures import scripted_server  # noqa: F401  (fixture for the LLM detector tests)


@pytest.fixture(scope="session")
def kb():
    from anomalygen.knowledge import load_kb

    return load_kb()
