"""Issue 39: every set's Self-BLEU and SBERT through one function, over seeded draws of equal size.

Tiny hand-made sets; SBERT is the shared encoder, loaded once per test process.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from anomalygen.embedding import embed, mean_pairwise_similarity
from anomalygen.evaluate.baselines import PAPER_DIVERSITY, baseline_records, baseline_texts
from anomalygen.evaluate.diversity import (
    DIVERSITY_HEADERS,
    PAPER_ENGINE_ROW,
    PUBLISHED_HEADER,
    baseline_rows,
    diversity_cells,
    text_row,
)
from anomalygen.evaluate.selfbleu import self_bleu
from anomalygen.evaluate.text_draws import TEXT_FIELD, Spread, drawn_text_metrics, set_texts

EIGHT = [
    "A knife lies on the kitchen counter next to the bread.",
    "The fridge door was left open after lunch.",
    "A toddler can reach the bleach under the sink.",
    "Pills are scattered on the bedroom floor.",
    "An extension cord runs across the hallway.",
    "The window in the nursery is wide open.",
    "A pan handle sticks out over the edge of the stove.",
    "Rotten fruit sits in the bowl on the dining table.",
]


def test_identical_texts_give_one_for_both_metrics():
    m = drawn_text_metrics(["a cat sat on the mat"] * 6, rng=np.random.default_rng(0), k=3, draws=4)
    assert m.self_bleu.mean == pytest.approx(1.0) and m.self_bleu.std == pytest.approx(0.0, abs=1e-12)
    assert m.sbert.mean == pytest.approx(1.0, abs=1e-5)
    assert (m.texts, m.k, m.draws, m.small_set) == (6, 3, 4, False)


def test_draws_are_reproducible_under_a_seed_and_are_the_generators_draws():
    a = drawn_text_metrics(EIGHT, rng=np.random.default_rng(7), k=4, draws=5)
    assert a == drawn_text_metrics(EIGHT, rng=np.random.default_rng(7), k=4, draws=5)
    assert a != drawn_text_metrics(EIGHT, rng=np.random.default_rng(8), k=4, draws=5)
    # the same numbers by hand: five draws of four indices without replacement from the same generator
    rng = np.random.default_rng(7)
    draws = [np.sort(rng.choice(8, size=4, replace=False)) for _ in range(5)]
    assert all(len(set(d)) == 4 for d in draws)
    vecs = embed(EIGHT)
    bleu = [self_bleu([EIGHT[i] for i in d]) for d in draws]
    sbert = [mean_pairwise_similarity(vecs[d]) for d in draws]
    assert a.self_bleu.mean == pytest.approx(math.fsum(bleu) / 5, abs=1e-12)
    assert a.self_bleu.std == pytest.approx(float(np.std(bleu, ddof=1)), abs=1e-12)
    assert a.sbert.mean == pytest.approx(float(np.mean(sbert)), abs=1e-6)
    assert a.self_bleu.low <= a.self_bleu.mean <= a.self_bleu.high and a.sbert.std > 0


def test_a_set_smaller_than_k_is_measured_whole_and_flagged():
    three = EIGHT[:3]
    m = drawn_text_metrics(three, rng=np.random.default_rng(0), k=50, draws=100)
    assert (m.texts, m.k, m.draws, m.small_set) == (3, 3, 1, True)
    assert m.self_bleu.mean == self_bleu(three) and m.self_bleu.std == 0.0
    assert m.sbert.mean == pytest.approx(mean_pairwise_similarity(embed(three)), abs=1e-6)
    # exactly k texts: every draw is the whole set, measured once, not flagged
    exact = drawn_text_metrics(EIGHT, rng=np.random.default_rng(0), k=8, draws=100)
    assert (exact.draws, exact.small_set) == (1, False)


def test_too_few_texts_or_bad_draws_are_refused():
    with pytest.raises(ValueError, match="at least two texts"):
        drawn_text_metrics(["alone"], rng=np.random.default_rng(0))
    with pytest.raises(ValueError, match="k >= 2"):
        drawn_text_metrics(EIGHT, rng=np.random.default_rng(0), k=1)


def test_spread():
    s = Spread.of([0.1, 0.2, 0.3])
    assert s.mean == pytest.approx(0.2) and s.std == pytest.approx(0.1)
    assert (s.low, s.high) == (pytest.approx(0.105), pytest.approx(0.295))
    assert Spread.of([0.4]) == Spread(0.4, 0.0, 0.4, 0.4)


def test_every_set_is_its_full_descriptions():
    from anomalygen.schema import TaskProposal

    assert TEXT_FIELD == "description"
    records = baseline_records("rlbench")
    assert baseline_texts("rlbench") == [r["description"] for r in records]
    assert baseline_texts("rlbench")[0] == "put the ball in the hoop"
    task = TaskProposal(id="t1", name="Knife at the edge", explanation="e", description=" A knife at the edge. ",
                        category="household_hazard", hazard_class="store_sharp_objects", target_asset="Knife",
                        scenario=dict(hazard_object="Knife", room="kitchen", placement="counter_edge"),
                        provenance=dict(engine="knowledge", mode="brainstorm"))
    assert set_texts([task, {"description": "b"}]) == ["A knife at the edge.", "b"]


def test_rows_carry_draws_and_the_published_figures_in_their_own_column():
    row = text_row("tiny", "run", EIGHT, seed=0, key="run", draw_size=4, draws=3, wmd_pairs=2)
    assert (row.draws, row.draw_size, row.small_set, row.text_field) == (3, 4, False, "description")
    assert row.self_bleu_std is not None and row.wmd is not None and row.published is None
    assert row == text_row("tiny", "run", EIGHT, seed=0, key="run", draw_size=4, draws=3, wmd_pairs=2)

    paper = baseline_rows(seed=0, measure=False)
    assert [r.name for r in paper][:2] == [PAPER_ENGINE_ROW, "RoboGen"]
    assert all(r.kind == "paper" and r.self_bleu is None and r.published is not None for r in paper)
    assert paper[0].published == PAPER_DIVERSITY["AnomalyGen"]

    assert DIVERSITY_HEADERS[-1] == PUBLISHED_HEADER == "as published; not reproducible from public code"
    small = text_row("small", "baseline", EIGHT[:3], seed=0, key="s", draw_size=50)
    cells = diversity_cells([row, small, paper[0]])
    assert cells[0][3] == "4 × 3 draws" and "±" in cells[0][4] and cells[0][-1] == "—"
    assert cells[1][3] == "all 3 (flagged: fewer than 50)" and "±" not in cells[1][4]
    assert cells[2][2:7] == ["—"] * 5 and cells[2][-1].startswith("Self-BLEU 0.227 · SBERT 0.245")


def test_evaluate_and_report_show_the_drawn_table_and_no_target_for_the_offline_engine(synthetic_run):
    from anomalygen.config import Settings
    from anomalygen.evaluate.report import run_stage as report_stage
    from anomalygen.evaluate.stage import evaluate_run, load_evaluation, run_stage

    s = Settings(quiet=True)
    s.evaluate.baselines = False
    s.evaluate.image_metrics = False
    s.evaluate.wmd_pairs = 5
    ev = evaluate_run(synthetic_run, s)
    run = ev.diversity[0]
    assert (run.kind, run.tasks, run.small_set, run.draws, run.published) == ("run", 5, True, 1, None)
    tasks = synthetic_run.load_tasks()
    assert run.self_bleu == self_bleu([t.description for t in tasks])
    assert [r.name for r in ev.diversity if r.published == PAPER_DIVERSITY["AnomalyGen"]] == [PAPER_ENGINE_ROW]
    run_stage(synthetic_run, s)
    assert load_evaluation(synthetic_run).diversity == ev.diversity
    report_stage(synthetic_run, s)
    html = (synthetic_run.report_dir / "index.html").read_text()
    diversity = html.split('id="diversity"')[1].split("</section>")[0]
    assert f"<th>{PUBLISHED_HEADER}</th>" in diversity and "all 5 (flagged: fewer than 50)" in diversity
    assert "target" not in diversity.replace("not a target for the offline engine", "")
