"""Resume against the settings in the detect stage: a changed key a detect item reads (``[detect]``,
the seed under perception noise, the LLM for the llm detectors) detects again; any other key does not."""

from __future__ import annotations

import pytest

from support.resume import LLM, assert_resume, cases, settings, stage_reads

# an LLM configured in every base, so that detect.detector can change to one that asks it
BASES = {
    "rules": {"llm": LLM},
    "noise": {"llm": LLM, "detect": {"noise": {"enabled": True}}},
    "llm": {"llm": LLM, "detect": {"detector": "llm"}},
}


@pytest.mark.parametrize(("base", "key", "redo"), cases("detect", BASES))
def test_scenes_are_detected_again_exactly_when_a_setting_they_read_changes(request, base, key, redo):
    assert_resume("detect", request, base, key, redo=redo)


def test_the_detect_stage_reads_the_seed_only_under_noise_and_the_llm_only_when_it_asks_one():
    rules = stage_reads("detect", settings(**BASES["rules"]))
    assert {"detect.detector", "detect.k", "detect.noise.pose_jitter"} <= set(rules)
    assert not [k for k in rules if not k.startswith("detect.")]
    assert "seed" in stage_reads("detect", settings(**BASES["noise"]))
    assert "llm.model" in stage_reads("detect", settings(**BASES["llm"]))
