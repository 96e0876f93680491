"""Paraphrases of an outside line read as the line does (issue 38).

Every line of ``benchmarks/data/outside_hazards.jsonl`` has three paraphrases in
``outside_paraphrases.jsonl``, written by a helper who saw only the line, never the reader. A reading is
the composed class, the object at fault (its kind when the lexicon has one, so "pills" and "tablets"
are one object), the related object and how it relates; or a refusal. The figures are scored in
aggregate, per half, so the held-out half is never read line by line; the floors are the measured
agreement at the commit that added them, and the README reports the figures.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_outside_text.py"
FLOORS = {"dev": 0.85, "held_out": 0.80}


@pytest.fixture(scope="module")
def agreement():
    spec = importlib.util.spec_from_file_location("bench_outside_text", BENCH)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    from anomalygen.brainstorm.free_text import TextGrounder
    from anomalygen.knowledge import load_kb

    kb = load_kb()
    tg = TextGrounder(kb, catalogue=set(kb.objects))
    return mod.paraphrase_agreement(mod.load_set("all"), tg)


@pytest.mark.parametrize("half", sorted(FLOORS))
def test_paraphrases_read_as_their_line(agreement, half):
    t = agreement[half]
    assert t["paraphrases"] >= 3 * t["lines"]  # three per line
    assert t["paraphrases_same"] / t["paraphrases"] >= FLOORS[half], t
