"""The LLM detector on the real bundled tiny GGUF (SmolLM2-135M): the mechanics, not the judgement."""

from __future__ import annotations

import detect_graphs as g
import pytest


@pytest.mark.slow
@pytest.mark.gguf
def test_llm_detector_runs_on_the_bundled_gguf(tmp_path, kb):
    from anomalygen.config import LLMConfig
    from anomalygen.detect.llm_detector import LLMDetector
    from anomalygen.llm import get_client

    client = get_client(LLMConfig(backend="llamacpp", cache=False, max_tokens=160, repair_retries=1))
    graph = g.pill_on_floor()
    hyps = LLMDetector(client, kb).detect(graph, 1)
    # grammar-constrained decoding against the per-scene schema: a real object and a known class or none
    assert len(hyps) == 1 and hyps[0].rank == 1
    names = {o.name for o in graph.objects} | {o.category for o in graph.objects}
    assert hyps[0].target_object in names
    assert hyps[0].hazard_class is None or hyps[0].hazard_class in kb.hazard_classes
    assert client.usage.requests >= 1 and client.usage.completion_tokens > 0
