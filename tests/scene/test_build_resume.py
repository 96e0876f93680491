"""Resume against the settings in the build stage: a changed key a build item reads (``[build]``, the
seed, the LLM where it lays out or checks the scene) rebuilds the scene; any other key does not."""

from __future__ import annotations

import pytest

from support.resume import LLM, assert_resume, cases, settings, stage_reads

BASES = {
    "knowledge": {},
    "llm_unasked": {"llm": LLM},
    "llm_layout": {"build": {"engine": "llm"}, "llm": LLM},
    "vlm_check": {"llm": {**LLM, "vision": True}},
}


@pytest.mark.parametrize(("base", "key", "redo"), cases("build", BASES))
def test_scenes_are_rebuilt_exactly_when_a_setting_they_read_changes(request, base, key, redo):
    assert_resume("build", request, base, key, redo=redo)


def test_the_build_stage_reads_build_and_the_seed_and_the_llm_only_where_it_asks_one():
    plain = stage_reads("build", settings())
    assert {"seed", "build.clutter", "build.start"} <= set(plain)
    assert [k for k in plain if not k.startswith("build.")] == ["seed"]  # no LLM: neither vision nor a backend
    # a configured LLM that is never asked (knowledge layout, no vision): only whether it would check
    assert set(stage_reads("build", settings(llm=LLM))) == {*plain, "llm.vision"}
    assert {"llm.model", "llm.vision"} <= set(stage_reads("build", settings(**BASES["vlm_check"])))
