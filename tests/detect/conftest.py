"""Fixtures for detection tests: the knowledge base and task proposals to judge against."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def kb():
    from anomalygen.knowledge import load_kb

    return load_kb()
