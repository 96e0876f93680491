"""The ablation ordering on a small sample: full brainstorming is more diverse than plain prompting."""

from __future__ import annotations

from anomalygen.brainstorm.ablation import format_table, run_ablation


def test_brainstorm_more_diverse_than_plain():
    result = run_ablation(seed=0, n_targets=10, runs=2, per_run=10, bleu=False)
    rows = {r.mode: r for r in result.rows}
    assert rows["plain"].proposals == rows["brainstorm"].proposals == 20
    assert rows["brainstorm"].sbert_similarity < rows["plain"].sbert_similarity
    assert rows["brainstorm"].distinct_scenarios >= rows["plain"].distinct_scenarios
    assert "brainstorm" in format_table(result)
