"""The executor behind every stage: inline, spawn process pool and Ray give identical artefacts."""

import json
import os
import tempfile

import pytest

from anomalygen.config import Settings
from anomalygen.errors import ItemFailed
from anomalygen.rng import item_rng
from anomalygen.runfolder import RunFolder, atomic_write_text
from anomalygen.runner import run_items

ITEMS = [(f"item{i}", {"scale": i}) for i in range(6)] + [("bad", {"scale": -1})]


def write_item(item_id, payload, ctx):
    """A real item function: seeded randomness, atomic output, an expected failure for one item."""
    if payload["scale"] < 0:
        raise ItemFailed("negative scale")
    rng = item_rng(ctx.settings.seed, ctx.stage, item_id)
    values = (rng.normal(size=5) * payload["scale"]).round(12).tolist()
    atomic_write_text(ctx.run.root / "out" / f"{item_id}.json", json.dumps({"id": item_id, "values": values}))
    return sum(values)


def _run(tmp_path, name, **kw):
    run = RunFolder.create(tmp_path / name)
    settings = Settings(quiet=True, seed=3, **kw)
    summary = run_items(run, "toy", ITEMS, write_item, settings=settings,
                        is_done=lambda i: (run.root / "out" / f"{i}.json").is_file())
    files = {p.name: p.read_text() for p in sorted((run.root / "out").glob("*.json"))}
    return run, summary, files


def test_inline_and_pool_identical_and_failure_isolated(tmp_path):
    run_a, sa, files_a = _run(tmp_path, "inline", workers=1)
    run_b, sb, files_b = _run(tmp_path, "pool", workers=2)
    assert files_a == files_b and len(files_a) == 6
    assert (sa.done, sa.failed) == (sb.done, sb.failed) == (6, 1)
    assert sa.results == sb.results
    assert [e.item_id for e in run_b.errors("toy")] == ["bad"]
    assert "negative scale" in run_b.errors("toy")[0].error
    # resume: everything done is skipped, only the failed item is retried
    again = run_items(run_b, "toy", ITEMS, write_item, settings=Settings(quiet=True, seed=3, workers=2),
                      is_done=lambda i: (run_b.root / "out" / f"{i}.json").is_file())
    assert (again.done, again.skipped, again.failed) == (0, 6, 1)


@pytest.mark.slow
@pytest.mark.ray
def test_ray_matches_local(tmp_path, monkeypatch):
    pytest.importorskip("ray")
    monkeypatch.setenv("RAY_AUTH_MODE", "disabled")
    # Ray's unix socket paths must stay under ~107 characters: a short folder directly in /tmp.
    monkeypatch.setenv("ANOMALYGEN_RAY_TMP", tempfile.mkdtemp(prefix="ray", dir="/tmp"))
    _, s_local, files_local = _run(tmp_path, "local", workers=2)
    _, s_ray, files_ray = _run(tmp_path, "ray", workers=2, executor="ray")
    assert files_ray == files_local
    assert (s_ray.done, s_ray.failed) == (6, 1) and s_ray.results == s_local.results
    assert "negative scale" in s_ray.errors["bad"]
    assert os.listdir(os.environ["ANOMALYGEN_RAY_TMP"])  # Ray's session files went to our temp folder
