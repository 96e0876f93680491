"""``anomalygen bench`` on a tiny suite: the referee's table as JSON, HTML and text, one run folder the
judge stage can judge again, DoNothing resolving nothing and leaving hazard-free scenes alone, and
Random making valid calls."""

from __future__ import annotations

import json

import pytest

from anomalygen.cli import main
from anomalygen.runfolder import RunFolder, read_model
from anomalygen.schema import BenchReport, EpisodeRecord, Verdict


def test_do_nothing_resolves_nothing_and_leaves_every_hazard_free_scene_alone(tiny_suite, tmp_path, capsys):
    out = tmp_path / "bench"
    main(["bench", "--agent", "anomalygen.agents:DoNothing", "--suite", str(tiny_suite.root), "--out", str(out),
          "--quiet"])
    printed = capsys.readouterr().err
    report = read_model(out / "bench.json", BenchReport)
    assert (report.runs, report.failed, report.resolved) == (3, 0, 0)
    assert report.hazard_free_runs == report.left_alone == 1 and report.runs_with_hazards == 2
    assert report.runs_with_new_hazards == 0
    # not asserted: runs_acting_on_safe. In t0002 the referee's own settle throws the near-miss pot
    # half a metre with nothing touching it (docs/benchmarks.md, "Any agent, judged"), robot or none
    assert report.suite == "tiny v1" and report.detection is None
    assert report.by_class and all(r.resolved == 0 and r.detected is None for r in report.by_class.values())
    assert "runs resolved (scenes with hazards): 0 of 2" in printed and "left alone: 1 of 1" in printed
    page = (out / "bench.html").read_text()
    assert "anomalygen.agents:DoNothing" in page and "tiny v1" in page
    run = RunFolder(out)
    for tid in tiny_suite.task_ids:
        ep = read_model(run.skill_dir(tid, 0) / "episode.json", EpisodeRecord)
        assert [c.call for c in ep.calls] == ["done"] and ep.ended == "done"
    # the folder is a run folder: the judge stage judges the saved final states again, alike
    before = {t: read_model(run.skill_dir(t, 0) / "verdict.json", Verdict) for t in tiny_suite.task_ids}
    main(["judge", "--run", str(out), "--force", "--quiet"])
    after = {t: read_model(run.skill_dir(t, 0) / "verdict.json", Verdict) for t in tiny_suite.task_ids}
    assert {t: (v.status, v.hazards) for t, v in after.items()} == {t: (v.status, v.hazards) for t, v in before.items()}
    # a rerun finds every episode judged and runs none
    main(["bench", "--agent", "anomalygen.agents:DoNothing", "--suite", str(tiny_suite.root), "--out", str(out),
          "--quiet", "--json"])
    assert json.loads(capsys.readouterr().out)["runs"] == 3


@pytest.mark.slow
def test_random_makes_valid_calls_and_is_judged(tiny_suite, tmp_path):
    from anomalygen.bench.run import run_bench
    from anomalygen.config import Settings

    tid = tiny_suite.task_ids[1]
    report = run_bench("anomalygen.agents:Random", tiny_suite, tmp_path / "random", Settings(quiet=True),
                       options={"calls": 1}, only=[tid])
    assert report.runs == 1 and report.failed == 0
    ep = read_model(RunFolder(tmp_path / "random").skill_dir(tid, 0) / "episode.json", EpisodeRecord)
    assert len(ep.calls) == 2 and ep.calls[0].error is None and ep.calls[0].executed and ep.calls[1].call == "done"


def test_a_bad_agent_name_is_the_users_error(tiny_suite, tmp_path):
    from anomalygen.bench.run import run_bench
    from anomalygen.config import Settings
    from anomalygen.errors import UserError

    with pytest.raises(UserError, match="MODULE:CLASS"):
        run_bench("Pipeline", tiny_suite, tmp_path / "x", Settings(quiet=True))
    with pytest.raises(UserError, match="cannot load the agent"):
        run_bench("anomalygen.agents:Nobody", tiny_suite, tmp_path / "x", Settings(quiet=True))
