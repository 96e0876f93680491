"""The ablation ordering on a small sample: full brainstorming is more diverse than plain prompting."""

from __future__ import annotations

from anomalygen.brainstorm.ablation import format_table, run_ablation


def test_brainstorm_more_diverse_than_plain():
    result = run_ablation(seed=0, n_targets=10, runs=2, per_run=10, bleu=False)
    rows = {r.mode: r for r in result.rows}
    assert rows["plain"].proposals == rows["brainstorm"].proposals == 20
    # Measured with 26 classes (60 proposals a mode, seeds 0-2): brainstorm covers more distinct
    # scenarios every time (47/42, 46/39, 44/40), while the mean SBERT similarity is level within noise
    # (0.328/0.322, 0.308/0.313, 0.344/0.330): the role agents diversify what the scenes are, the
    # realiser's wording keeps the embeddings close. The test holds the first and bounds the second.
    assert rows["brainstorm"].distinct_scenarios > rows["plain"].distinct_scenarios
    assert rows["brainstorm"].sbert_similarity < rows["plain"].sbert_similarity + 0.02
    assert "brainstorm" in format_table(result)
