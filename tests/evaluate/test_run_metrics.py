"""Counting metrics on a hand-built run: distributions, hit@k, success by category and class."""

import pytest

from anomalygen.evaluate import run_metrics as rm
from anomalygen.evaluate.baselines import BASELINES, PAPER_DIVERSITY, baseline_records, baseline_texts
from anomalygen.evaluate.text_metrics import sample_pairs, task_text


def test_distributions(synthetic_run):
    tasks = rm.load_tasks(synthetic_run)
    assert rm.category_distribution(tasks) == {"child_safety": 2, "household_hazard": 2, "hygiene": 1}
    assert sum(rm.class_distribution(tasks).values()) == 5


def test_hit_at_k(synthetic_run):
    tasks = rm.load_tasks(synthetic_run)
    summary = rm.detection_summary(rm.load_detections(synthetic_run), tasks, k=3)
    # hit ranks: 1, 2, 1, miss, 3
    assert summary.hit_at_k == {1: pytest.approx(0.4), 2: pytest.approx(0.6), 3: pytest.approx(0.8)}
    assert summary.by_category["hygiene"][1] == 1.0
    assert summary.by_category["household_hazard"] == {1: 0.0, 2: 0.5, 3: 1.0}


def test_success_by_category_and_class(synthetic_run):
    tasks = rm.load_tasks(synthetic_run)
    s = rm.success_summary(rm.load_skill_results(synthetic_run), tasks)
    assert (s.overall.n, s.overall.successes) == (5, 3)
    assert s.by_category["child_safety"].rate == 1.0
    assert s.by_category["hygiene"].rate == 0.0
    assert s.by_class["fire"].successes == 0 and s.by_class["choking"].successes == 1
    assert s.by_method["primitive"].rate == 1.0 and s.by_method["sac"].successes == 3


def test_missing_stages_give_empty_inputs(tmp_path):
    from anomalygen.runfolder import RunFolder

    run = RunFolder.create(tmp_path / "empty")
    assert rm.load_tasks(run) == [] and rm.load_detections(run) == [] and rm.load_skill_results(run) == []
    assert rm.scene_renders(run) == []


def test_baselines_are_packaged_with_sources():
    counts = {stem: len(baseline_records(stem)) for stem in BASELINES}
    assert counts == {"robogen": 46, "behavior100": 100, "rlbench": 106, "metaworld": 50, "maniskill2": 20, "gensim": 70}
    assert all(r["source"] for stem in BASELINES for r in baseline_records(stem))
    assert set(BASELINES.values()) | {"AnomalyGen"} == set(PAPER_DIVERSITY)
    assert baseline_texts("rlbench")[0] == "basketball in hoop. put the ball in the hoop"


def test_task_text_does_not_repeat_names():
    assert task_text("assembling_gift_baskets", "assembling gift baskets") == "assembling gift baskets"
    assert task_text("knife_at_edge", "A knife.") == "knife at edge. A knife."


def test_sample_pairs_is_seeded_and_distinct():
    import numpy as np

    a = sample_pairs(50, 100, np.random.default_rng(3))
    b = sample_pairs(50, 100, np.random.default_rng(3))
    assert a == b and len(set(a)) == 100 and all(0 <= i < j < 50 for i, j in a)
    assert len(sample_pairs(5, 100, np.random.default_rng(0))) == 10


def test_mixed_brainstorm_modes_get_ablation_rows(tmp_path):
    from anomalygen.config import Settings
    from anomalygen.evaluate.stage import evaluate_run
    from anomalygen.runfolder import write_jsonl

    from .conftest import build_synthetic_run

    run = build_synthetic_run(tmp_path / "modes", stages=("brainstorm",))
    tasks = rm.load_tasks(run)
    for t in tasks[:2]:
        t.provenance.mode = "plain"
    write_jsonl(run.tasks_path, tasks)
    s = Settings(quiet=True)
    s.evaluate.baselines = False
    s.evaluate.wmd_pairs = 5
    rows = {r.name: r for r in evaluate_run(run, s).diversity if r.kind == "run"}
    assert set(rows) == {"modes", "modes [mode=plain]", "modes [mode=brainstorm]"}
    assert rows["modes [mode=plain]"].tasks == 2 and rows["modes [mode=brainstorm]"].tasks == 3


def test_the_referees_verdict_is_counted_apart_from_the_robots_own():
    from anomalygen.schema import FixOutcome, HazardOutcome, HazardVerdict, SkillResult, TaskProposal, Verdict

    def task(tid, cls):
        return TaskProposal(id=tid, name="n", explanation="e", description="d", category="hygiene",
                            hazard_class=cls, target_asset="TrashCan",
                            scenario=dict(hazard_object="rotten_apple", room="kitchen", placement="table"),
                            provenance=dict(engine="knowledge", mode="brainstorm"))

    def verdict(tid, seed, ok, new=(), safe=(), hazards=True):
        hs = [HazardVerdict(hazard_class="c", object="o", resolved=ok and not new)] if hazards else []
        status = ("resolved" if ok and not new else "unresolved") if hazards else (
            "acted_on_safe" if safe else "no_action_needed")
        return Verdict(task_id=tid, seed=seed, status=status, resolved=hazards and ok and not new, hazards=hs,
                       new_hazards=list(new), interventions_on_safe=list(safe))

    results = [
        SkillResult(task_id="a", seed=0, success=True),
        SkillResult(task_id="a", seed=1, success=True),  # fooled itself: it made a new hazard
        SkillResult(task_id="b", seed=0, success=False),
        SkillResult(task_id="b", seed=1, success=True),  # no verdict: not judged
        SkillResult(task_id="c", seed=0, success=True),  # a hazard-free scene, left alone: never "resolved"
        # an old run, judged inside learn: its outcome is read as a verdict
        SkillResult(task_id="d", seed=0, success=True, outcome=FixOutcome(
            hazards=[HazardOutcome(hazard_class="c", object="o", resolved=True)], resolved=True)),
    ]
    verdicts = {("a", 0): verdict("a", 0, True), ("a", 1): verdict("a", 1, True, new=["x on y"]),
                ("b", 0): verdict("b", 0, False, safe=["mug_0"]), ("c", 0): verdict("c", 0, True, hazards=False)}
    tasks = [task("a", "dispose_spoiled_food"), task("b", "store_sharp_objects"), task("c", "store_sharp_objects"),
             task("d", "store_sharp_objects")]
    s = rm.success_summary(results, tasks, verdicts)
    assert (s.overall.successes, s.overall.n) == (5, 6)  # the robot's own check, beside the verdict
    assert (s.resolved.successes, s.resolved.n) == (2, 4)
    assert s.resolved_by_class["dispose_spoiled_food"].rate == 0.5 and s.resolved_by_class["store_sharp_objects"].n == 2
    assert (s.new_hazards, s.on_safe) == (1, 1)
    assert (s.hazard_free_runs, s.no_action_needed, s.acted_on_safe) == (1, 1, 0)


def test_hazard_free_scenes_are_left_out_of_hit_at_k():
    from anomalygen.schema import Detection, Hypothesis

    hit = Detection(task_id="a", scene_id="s", detector="rules", hit_rank=1,
                    hypotheses=[Hypothesis(rank=1, problem="p", solution="s", target_object="k_0")])
    quiet = Detection(task_id="b", scene_id="s2", detector="rules", hazard_free=True, hypotheses=[])
    assert rm.hit_at_k([hit, quiet], 2) == {1: 1.0, 2: 1.0}
