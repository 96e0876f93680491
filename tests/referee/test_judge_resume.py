"""Resume against the settings in the judge stage: the referee judges from the files alone, so no
setting redoes a verdict (a changed scene, truth or end state does: tests/referee/test_judge_built_scenes.py)."""

from __future__ import annotations

import pytest

from support.resume import LLM, assert_resume, cases, settings, stage_reads

BASES = {"default": {}, "llm": {"llm": LLM, "plan": {"engine": "llm"}, "detect": {"detector": "llm"}}}


@pytest.mark.parametrize(("base", "key", "redo"), cases("judge", BASES))
def test_verdicts_are_redone_by_no_setting(request, base, key, redo):
    assert_resume("judge", request, base, key, redo=redo)


def test_the_judge_stage_reads_no_setting():
    assert all(stage_reads("judge", settings(**over)) == [] for over in BASES.values())
