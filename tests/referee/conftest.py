"""Fixtures for the referee's tests: the knowledge base, and the hand-built graphs of tests/detect."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "detect"))  # detect_graphs: shared hand-built graphs


@pytest.fixture(scope="session")
def kb():
    from anomalygen.knowledge import load_kb

    return load_kb()
