"""Unit tests of the pure parts: JSON extraction, bounded schemas, the SQLite cache across processes."""

from __future__ import annotations

import multiprocessing as mp

import pytest

from anomalygen.llm.cache import ReplyCache, cache_key
from anomalygen.llm.jsonextract import JSONExtractError, extract_json
from anomalygen.llm.schema_tools import bounded_schema
from anomalygen.schema import SceneSpec, TaskProposal


@pytest.mark.parametrize(
    ("reply", "value"),
    [
        ('{"a": 1}', {"a": 1}),
        ('Here you go:\n```json\n{"a": [1, 2]}\n```\nbye', {"a": [1, 2]}),
        ('noise {"a": "}"} more {"b": 2}', {"a": "}"}),
        ("[1, 2]", [1, 2]),
        ('list: [] then {"a": 1}', {"a": 1}),
    ],
)
def test_extract_json_finds_the_value(reply, value):
    assert extract_json(reply) == value


@pytest.mark.parametrize(
    ("reply", "reason"),
    [
        ("", "empty"),
        ('{"a": 1', "truncated"),
        ("no json here", "no JSON object"),
        ("x" * 500_001, "too long"),
    ],
)
def test_extract_json_explains_failure(reply, reason):
    with pytest.raises(JSONExtractError, match=reason):
        extract_json(reply)


def _walk(node):
    if isinstance(node, dict):
        yield node
        for v in node.values():
            yield from _walk(v)
    elif isinstance(node, list):
        for v in node:
            yield from _walk(v)


def test_bounded_schema_caps_strings_and_arrays_and_is_self_contained():
    schema = bounded_schema(TaskProposal, max_string=50, max_items=2, required_only=False)
    nodes = list(_walk(schema))
    assert not any("$ref" in n or "$defs" in n for n in nodes)
    strings = [n for n in nodes if n.get("type") == "string" and "enum" not in n]
    assert strings and all(n["maxLength"] == 50 for n in strings)
    arrays = [n for n in nodes if n.get("type") == "array"]
    assert arrays and all(n["maxItems"] == 2 for n in arrays)
    assert schema["additionalProperties"] is False and "scenario" in schema["properties"]
    assert set(schema["properties"]["scenario"]["properties"]) >= {"hazard_object", "container"}
    required_only = bounded_schema(TaskProposal)
    assert set(required_only["properties"]) == set(TaskProposal.model_json_schema()["required"])


def test_bounded_schema_keeps_fixed_length_vectors():
    schema = bounded_schema(SceneSpec, max_items=2, required_only=False)
    pos = schema["properties"]["objects"]["items"]["properties"]["pos"]
    assert pos["minItems"] == 3 and pos["maxItems"] == 3


def test_cache_key_is_canonical():
    assert cache_key({"a": 1, "b": [1, 2]}) == cache_key({"b": [1, 2], "a": 1})
    assert cache_key({"a": 1}) != cache_key({"a": 2})


def _writer(path: str, worker: int, n: int) -> int:
    cache = ReplyCache(path)
    for i in range(n):
        cache.put(cache_key({"w": worker, "i": i}), f"reply {worker}/{i}", i, 1)
        assert cache.get(cache_key({"w": worker, "i": i})) == (f"reply {worker}/{i}", i, 1)
    return n


def test_cache_is_safe_across_processes(tmp_path):
    path = str(tmp_path / "shared.sqlite")
    ReplyCache(path)
    ctx = mp.get_context("spawn")
    with ctx.Pool(2) as pool:
        counts = pool.starmap(_writer, [(path, w, 150) for w in range(2)])
    assert counts == [150, 150]
    cache = ReplyCache(path)
    assert len(cache) == 300
    assert cache.get(cache_key({"w": 1, "i": 149})) == ("reply 1/149", 149, 1)


@pytest.mark.parametrize("name", sorted(__import__("anomalygen.schema", fromlist=["ARTEFACTS"]).ARTEFACTS))
def test_every_artefact_schema_converts_to_a_llama_grammar(name):
    """Any stage may ask the llamacpp backend for any artefact: its bounded schema must become a grammar."""
    import xllamacpp

    from anomalygen.schema import ARTEFACTS

    schema = bounded_schema(ARTEFACTS[name], max_string=80, max_items=2, required_only=False)
    grammar = xllamacpp.json_schema_to_grammar(schema)
    assert grammar.strip() and "properties" in grammar


def test_llamacpp_threads_leave_a_core_to_the_rest_of_the_pipeline(monkeypatch):
    """Two llama.cpp threads beside a busy simulator on two cores ran the GGUF tests ~5x slower than one."""
    import os

    from anomalygen.config import LLMConfig
    from anomalygen.llm.local_server import LocalServer, default_threads

    for cores, want in ((1, 1), (2, 1), (3, 2), (8, 4)):
        monkeypatch.setattr(os, "sched_getaffinity", lambda _pid, n=cores: set(range(n)), raising=False)
        assert default_threads() == want
        assert LocalServer("m.gguf", n_ctx=256).threads == want
    assert LocalServer("m.gguf", n_ctx=256, threads=3).threads == 3
    assert LLMConfig(backend="llamacpp", threads=2).threads == 2
