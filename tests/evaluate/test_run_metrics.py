"""Counting metrics on a hand-built run: distributions, hit@k, success by category and class."""

import pytest

from anomalygen.evaluate import run_metrics as rm
from anomalygen.evaluate.baselines import BASELINES, PAPER_DIVERSITY, baseline_records, baseline_texts
from anomalygen.evaluate.text_metrics import sample_pairs


def test_distributions(synthetic_run):
    tasks = rm.load_tasks(synthetic_run)
    assert rm.category_distribution(tasks) == {"child_safety": 2, "household_hazard": 2, "hygiene": 1}
    assert sum(rm.class_distribution(tasks).values()) == 5


def test_detection_is_scored_against_the_truth(synthetic_run):
    from anomalygen.evaluate.detection_report import summarise

    tasks = rm.load_tasks(synthetic_run)
    report = summarise(rm.load_detections(synthetic_run), tasks, rm.load_manifests(synthetic_run, tasks), 3,
                       category_of={t.hazard_class: str(t.category) for t in tasks})
    sc = report.overall
    # the truth hazard is named at ranks 1, 2, 1, never, 3; every other claim is one decoy
    assert (sc.hazards, sc.found) == (5, 4) and sc.recall == 0.8
    assert (sc.true_claims, sc.claims) == (4, 9)
    assert sc.hit_at_k == {1: pytest.approx(0.4), 2: pytest.approx(0.6), 3: pytest.approx(0.8)}
    assert report.per_category["hygiene"] == {"close_open_refrigerator": rm_found(1, 1)}
    assert report.per_category_found()["child_safety"] == rm_found(2, 1)
    assert report.confusion["keep_chemicals_from_children"] == {"none": 1}
    (miss,) = report.misses
    assert miss.task_id == "bleach_low_shelf" and miss.object == "bottle_0" and "decoy_0" in miss.claims


def rm_found(hazards, found):
    from anomalygen.evaluate.rate import Rate

    return Rate(n=hazards, successes=found)


def test_headlines_are_the_referees_verdicts_with_the_robots_own_beside(synthetic_run):
    tasks = rm.load_tasks(synthetic_run)
    results = rm.load_skill_results(synthetic_run)
    s = rm.success_summary(results, tasks, rm.load_verdicts(synthetic_run, results))
    assert (s.verdicts.resolved, s.verdicts.hazard_runs) == (2, 5)  # the referee: pill and bleach
    assert (s.robot_check.successes, s.robot_check.n) == (3, 5)  # the robot also believes the knife
    assert s.by_category["child_safety"].rate == 1.0 and s.by_category["household_hazard"].rate == 0.0
    assert s.by_class["store_sharp_objects"].unresolved == 1 and s.robot_check_by_class["store_sharp_objects"].successes == 1
    assert s.class_category["switch_off_appliance"] == "household_hazard"
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
    assert baseline_texts("behavior100")[0] == "assembling gift baskets"  # its only text: the activity name


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


def test_the_truth_verdict_is_counted_apart_from_the_robots_own():
    from anomalygen.evaluate.verdicts import from_outcome
    from anomalygen.schema import FixOutcome, HazardOutcome, SkillResult, TaskProposal

    def task(tid, cls):
        return TaskProposal(id=tid, name="n", explanation="e", description="d", category="hygiene",
                            hazard_class=cls, target_asset="TrashCan",
                            scenario=dict(hazard_object="rotten_apple", room="kitchen", placement="table"),
                            provenance=dict(engine="knowledge", mode="brainstorm"))

    def verdict(ok, new=(), safe=(), hazards=True):
        found = [HazardOutcome(hazard_class="c", object="o", resolved=ok)] if hazards else []
        return FixOutcome(hazards=found, resolved=ok, new_hazards=list(new), interventions_on_safe=list(safe))

    results = [
        SkillResult(task_id="a", seed=0, success=True, outcome=verdict(True)),
        SkillResult(task_id="a", seed=1, success=True, outcome=verdict(True, new=["x on y"])),  # fixed, broke another
        SkillResult(task_id="b", seed=0, success=False, outcome=verdict(False, safe=["mug_0"])),
        SkillResult(task_id="b", seed=1, success=True),  # no truth.json: not judged
        SkillResult(task_id="c", seed=0, success=True, outcome=verdict(True, hazards=False)),  # nothing to do
        SkillResult(task_id="c", seed=1, success=True, outcome=verdict(True, safe=["mug_0"], hazards=False)),
    ]
    verdicts = {(r.task_id, r.seed): from_outcome(r.outcome) if r.outcome else None for r in results}
    s = rm.success_summary(results, [task("a", "dispose_spoiled_food"), task("b", "store_sharp_objects"),
                                     task("c", "store_sharp_objects")], verdicts)
    assert (s.robot_check.successes, s.robot_check.n) == (5, 6)
    # a new hazard counts against the run; a hazard-free scene is never "resolved"
    assert (s.verdicts.resolved, s.verdicts.hazard_runs, s.verdicts.runs, s.unjudged) == (1, 3, 5, 1)
    assert (s.verdicts.no_action_needed, s.verdicts.acted_on_safe) == (1, 1)
    assert s.by_class["dispose_spoiled_food"].rate == 0.5 and s.by_class["store_sharp_objects"].hazard_runs == 1
    assert (s.verdicts.new_hazards, s.verdicts.on_safe) == (1, 2)


def test_a_hazard_free_scene_reads_no_action_needed_or_acted_on_safe():
    from anomalygen.evaluate.verdicts import from_outcome
    from anomalygen.schema import FixOutcome

    assert from_outcome(FixOutcome(resolved=True)).status == "no_action_needed"
    left = from_outcome(FixOutcome(resolved=True, new_hazards=["store_sharp_objects on knife_0"]))
    assert left.status == "acted_on_safe" and not left.resolved
