"""A tiny suite, built once per session the way named suites are built: the first three seed-0 tasks
of the knowledge engine (one of them drawn hazard-free by the default judgement mix)."""

from __future__ import annotations

import pytest

# hazard_free 0.3: the share that draws exactly one of the three hazard-free (the draw is keyed by the
# task's id, which changes with its words; the default 0.15 drew none once the texts were rewritten)
TINY = dict(name="tiny", version=1, description="the first three seed-0 knowledge-engine tasks", source="tests", n=3,
            build={"hazard_free": 0.3})


@pytest.fixture(scope="session")
def tiny_def():
    from anomalygen.bench.suites import SuiteDef

    return SuiteDef(**TINY)


@pytest.fixture(scope="session")
def tiny_suite(tmp_path_factory, tiny_def):
    from anomalygen.bench.suites import build_suite, open_suite

    folder = tmp_path_factory.mktemp("tiny_suite")
    build_suite(tiny_def, folder, quiet=True)
    return open_suite(folder)
