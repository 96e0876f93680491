"""Fixtures for the referee's tests: the knowledge base."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def kb():
    from anomalygen.knowledge import load_kb

    return load_kb()
