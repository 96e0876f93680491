"""The openai backend and the client around it, against a real scripted HTTP server on 127.0.0.1."""

from __future__ import annotations

import json
import threading
import time

import numpy as np
import pytest
from llm_helpers import USER, VALID, VALID_TEXT, complete_in_child

from anomalygen.config import LLMConfig, Settings
from anomalygen.errors import ItemFailed, UserError
from anomalygen.llm import LLMItemError, get_client, make_backend, record_usage
from anomalygen.llm.client import LLMClient
from anomalygen.runfolder import RunFolder
from anomalygen.schema import Scenario
from support.fixtures import llm_config_for
from support.openai_server import hang, status, text


def client_for(srv, tmp_path, **overrides):
    from support.fixtures import llm_config_for

    return get_client(llm_config_for(srv, tmp_path, **overrides), backoff_base_s=0.01)


def test_schema_completion_returns_validated_model_and_counts_usage(scripted_server, tmp_path):
    srv = scripted_server([text(VALID_TEXT, prompt_tokens=100, completion_tokens=20)])
    client = client_for(srv, tmp_path, price_prompt_per_mtok=2.0, price_completion_per_mtok=10.0)
    result = client.complete(USER, schema=Scenario, temperature=0.2, seed=7, max_tokens=300)
    assert isinstance(result, Scenario) and result.hazard_object == "knife"
    body = srv.requests[0]
    assert body["response_format"]["type"] == "json_schema"
    assert body["response_format"]["json_schema"]["schema"]["required"] == [
        "hazard_object",
        "room",
        "placement",
    ]
    assert (body["temperature"], body["seed"], body["max_tokens"]) == (0.2, 7, 300)
    assert body["messages"][0]["role"] == "system" and "Scenario" in body["messages"][0]["content"]
    assert body["messages"][-1] == USER[0]
    u = client.usage
    assert (u.requests, u.prompt_tokens, u.completion_tokens, u.cache_misses, u.retries) == (1, 100, 20, 1, 0)
    assert u.cost_usd == pytest.approx((100 * 2.0 + 20 * 10.0) / 1e6)


def test_plain_completion_returns_text(scripted_server, tmp_path):
    srv = scripted_server([text("pong")])
    assert client_for(srv, tmp_path).complete(USER) == "pong"
    assert "response_format" not in srv.requests[0]


def test_falls_back_to_json_mode_when_server_rejects_json_schema(scripted_server, tmp_path):
    def responder(body):
        if body.get("response_format", {}).get("type") == "json_schema":
            return status(400, json.dumps({"error": {"message": "response_format json_schema unsupported"}}))
        return text(VALID_TEXT)

    srv = scripted_server(responder)
    client = client_for(srv, tmp_path, cache=False)
    assert client.complete(USER, schema=Scenario).room == "kitchen"
    assert [r["response_format"]["type"] for r in srv.requests] == ["json_schema", "json_object"]
    # the client remembers: the next request goes straight to JSON mode
    client.complete(USER + [{"role": "user", "content": "again"}], schema=Scenario)
    assert srv.requests[-1]["response_format"]["type"] == "json_object"
    assert client.usage.retries == 0  # a fallback is not a retry


def test_repair_loop_sends_validation_error_back(scripted_server, tmp_path):
    bad = json.dumps({"hazard_object": "knife", "room": 3, "placement": "floor", "colour": "red"})
    srv = scripted_server([text(bad), text("```json\n" + VALID_TEXT + "\n```")])
    client = client_for(srv, tmp_path)
    assert client.complete(USER, schema=Scenario) == Scenario(**VALID)
    assert len(srv.requests) == 2
    second = srv.requests[1]["messages"]
    assert second[-2] == {"role": "assistant", "content": bad}
    repair = second[-1]["content"]
    assert "room: Input should be a valid string" in repair
    assert "unknown field 'colour' is not allowed" in repair
    assert client.usage.retries == 1 and client.usage.requests == 2


def test_repair_exhaustion_raises_item_error_with_one_line(scripted_server, tmp_path):
    srv = scripted_server([text("I am sorry, I cannot help\nwith that.")])
    client = client_for(srv, tmp_path, repair_retries=2)
    with pytest.raises(LLMItemError) as info:
        client.complete(USER, schema=Scenario)
    assert isinstance(info.value, ItemFailed)
    msg = str(info.value)
    assert "\n" not in msg and "not a valid Scenario after 3 attempt(s)" in msg and "no JSON object" in msg
    assert len(srv.requests) == 3


@pytest.mark.parametrize("code", [429, 500, 503])
def test_retries_transient_status_then_succeeds(scripted_server, tmp_path, code):
    srv = scripted_server([status(code), status(code), text(VALID_TEXT)])
    client = client_for(srv, tmp_path, http_retries=3)
    assert client.complete(USER, schema=Scenario).placement.key == "counter_edge"
    assert len(srv.requests) == 3
    assert client.usage.retries == 2 and client.usage.requests == 1


def test_retries_exhausted_is_item_error(scripted_server, tmp_path):
    srv = scripted_server([status(500)])
    client = client_for(srv, tmp_path, http_retries=2)
    with pytest.raises(LLMItemError, match=r"failed after 3 attempt\(s\): HTTP 500"):
        client.complete(USER, schema=Scenario)
    assert len(srv.requests) == 3


def test_non_retryable_status_fails_at_once(scripted_server, tmp_path):
    srv = scripted_server([status(401, json.dumps({"error": {"message": "bad key"}}))])
    client = client_for(srv, tmp_path, http_retries=3)
    with pytest.raises(LLMItemError, match="HTTP 401: bad key"):
        client.complete(USER)
    assert len(srv.requests) == 1


def test_timeout_on_hang_then_retry(scripted_server, tmp_path):
    srv = scripted_server([hang(10.0), text(VALID_TEXT)])
    client = client_for(srv, tmp_path, timeout_s=0.4, http_retries=1)
    start = time.perf_counter()
    assert client.complete(USER, schema=Scenario).room == "kitchen"
    assert time.perf_counter() - start < 5.0
    assert len(srv.requests) == 2 and client.usage.retries == 1


def test_cache_hit_skips_http_and_param_change_misses(scripted_server, tmp_path):
    srv = scripted_server([text(VALID_TEXT)])
    client = client_for(srv, tmp_path)
    first = client.complete(USER, schema=Scenario, temperature=0.1, seed=1)
    again = client_for(srv, tmp_path).complete(
        USER, schema=Scenario, temperature=0.1, seed=1
    )  # new client, same file
    assert first == again and len(srv.requests) == 1
    client.complete(USER, schema=Scenario, temperature=0.1, seed=1)
    assert (client.usage.cache_hits, client.usage.cache_misses, client.usage.requests) == (1, 1, 1)
    for change in (
        {"temperature": 0.3, "seed": 1},
        {"temperature": 0.1, "seed": 2},
        {"temperature": 0.1, "seed": 1, "max_tokens": 9},
    ):
        client.complete(USER, schema=Scenario, **change)
    client.complete(USER, temperature=0.1, seed=1)  # no schema: a different key too
    assert len(srv.requests) == 5 and client.usage.cache_misses == 5


def test_no_cache_bypasses_cache(scripted_server, tmp_path):
    srv = scripted_server([text(VALID_TEXT)])
    client = client_for(srv, tmp_path, cache=False)
    client.complete(USER, schema=Scenario)
    client.complete(USER, schema=Scenario)
    assert len(srv.requests) == 2
    assert (client.usage.cache_hits, client.usage.cache_misses) == (0, 0)
    assert not (tmp_path / "llm-cache.sqlite").exists()
    cached = client_for(srv, tmp_path)
    cached.complete(USER, schema=Scenario)
    cached.complete(USER, schema=Scenario, cache=False)  # per-call bypass
    assert len(srv.requests) == 4


def test_concurrency_bound_respected(scripted_server, tmp_path):
    lock = threading.Lock()
    state = {"now": 0, "max": 0}

    def responder(body):
        with lock:
            state["now"] += 1
            state["max"] = max(state["max"], state["now"])
        time.sleep(0.15)
        with lock:
            state["now"] -= 1
        return text(VALID_TEXT)

    srv = scripted_server(responder)
    client = client_for(srv, tmp_path, concurrency=2, cache=False)
    batch = [[{"role": "user", "content": f"scene {i}"}] for i in range(8)]
    results = client.complete_many(batch, schema=Scenario)
    assert all(isinstance(r, Scenario) for r in results) and len(results) == 8
    assert state["max"] == 2


def test_complete_many_keeps_failures_per_item(scripted_server, tmp_path):
    def responder(body):
        return text("not json at all") if "bad" in body["messages"][-1]["content"] else text(VALID_TEXT)

    srv = scripted_server(responder)
    client = client_for(srv, tmp_path, repair_retries=0)
    batch = [[{"role": "user", "content": c}] for c in ("good 1", "bad", "good 2")]
    results = client.complete_many(batch, schema=Scenario)
    assert isinstance(results[0], Scenario) and isinstance(results[2], Scenario)
    assert isinstance(results[1], LLMItemError)


def test_api_key_never_in_cache_errors_or_run_folder(scripted_server, tmp_path):
    secret = "sk-very-secret-0123456789"
    echo = json.dumps({"error": {"message": f"invalid api key {secret}"}})
    srv = scripted_server([text(VALID_TEXT), status(401, echo)])
    client = client_for(srv, tmp_path, api_key=secret)
    client.complete(USER, schema=Scenario)
    assert srv.headers[0]["authorization"] == f"Bearer {secret}"  # it is sent, and only sent
    with pytest.raises(LLMItemError) as info:
        client.complete(USER + [{"role": "user", "content": "more"}], schema=Scenario)
    assert secret not in str(info.value) and "***" in str(info.value)
    cache_bytes = b"".join(p.read_bytes() for p in tmp_path.glob("llm-cache.sqlite*"))
    assert cache_bytes and secret.encode() not in cache_bytes
    settings = Settings(llm=client.config)
    run = RunFolder.create(tmp_path / "run", settings=settings)
    record_usage(run, client.usage)
    for path in (tmp_path / "run").rglob("*"):
        if path.is_file():
            assert secret not in path.read_text(errors="replace")


def test_record_usage_accumulates_into_manifest(scripted_server, tmp_path):
    srv = scripted_server([text(VALID_TEXT, prompt_tokens=10, completion_tokens=5)])
    client = client_for(srv, tmp_path, price_prompt_per_mtok=1.0)
    client.complete(USER, schema=Scenario)
    client.complete(USER, schema=Scenario)  # cache hit
    run = RunFolder.create(tmp_path / "run")
    record_usage(run, client.usage)
    total = record_usage(run, client.reset_usage())
    m = run.load_manifest().llm_usage
    assert m == total
    assert (m.requests, m.prompt_tokens, m.completion_tokens, m.cache_hits, m.cache_misses) == (
        2,
        20,
        10,
        2,
        2,
    )
    assert m.cost_usd == pytest.approx(2 * 10 / 1e6)
    assert client.usage.requests == 0


def test_backoff_is_exponential_and_jitter_comes_from_the_generator(scripted_server, tmp_path):
    from support.fixtures import llm_config_for

    srv = scripted_server([status(429), status(429), status(429), text("ok")])
    config = llm_config_for(srv, tmp_path, http_retries=3, cache=False)
    slept: list[float] = []
    client = LLMClient(config, make_backend(config), backoff_base_s=0.5, sleep=slept.append)
    assert client.complete(USER) == "ok"
    assert slept == [0.5, 1.0, 2.0]

    def jittered(seed):
        c = LLMClient(
            config,
            make_backend(config),
            rng=np.random.default_rng(seed),
            backoff_base_s=0.5,
            sleep=lambda s: None,
        )
        return [c._backoff(i) for i in range(4)]

    assert jittered(3) == jittered(3) != jittered(4)
    assert all(0.5 * 2**i <= d <= 0.5 * 2**i * 1.25 for i, d in enumerate(jittered(3)))


def test_backend_none_is_a_user_error_with_hint():
    with pytest.raises(UserError, match="--backend openai"):
        get_client(LLMConfig())


def test_images_are_sent_as_data_uris(scripted_server, tmp_path):
    srv = scripted_server([text("a red cube")])
    client = client_for(srv, tmp_path, vision=True)
    png = b"\x89PNG\r\n\x1a\n" + b"\x00" * 16
    assert client.supports_images
    assert client.complete(USER, images=[png]) == "a red cube"
    parts = srv.requests[0]["messages"][-1]["content"]
    assert parts[0]["type"] == "text" and parts[1]["image_url"]["url"].startswith("data:image/png;base64,")


def test_failed_conversation_is_not_cached_but_repaired_one_replays(scripted_server, tmp_path):
    srv = scripted_server([text("nonsense"), text("nonsense")])
    with pytest.raises(LLMItemError):
        client_for(srv, tmp_path, repair_retries=1).complete(USER, schema=Scenario)
    assert len(srv.requests) == 2

    srv2 = scripted_server([text("still nonsense"), text(VALID_TEXT)])
    client = client_for(srv2, tmp_path, repair_retries=1)
    assert client.complete(USER, schema=Scenario).room == "kitchen"  # asked afresh, repaired
    assert len(srv2.requests) == 2

    replay = client_for(srv2, tmp_path, repair_retries=1)
    assert replay.complete(USER, schema=Scenario).room == "kitchen"
    assert len(srv2.requests) == 2  # the whole repair conversation came from the cache
    assert (replay.usage.cache_hits, replay.usage.requests) == (2, 0)


def test_images_need_a_vision_endpoint(scripted_server, tmp_path):
    srv = scripted_server([text("x")])
    with pytest.raises(UserError, match="does not take images"):
        client_for(srv, tmp_path).complete(USER, images=[b"\x89PNG\r\n\x1a\n"])
    assert srv.requests == []


def test_unrelated_400_does_not_downgrade_structured_mode(scripted_server, tmp_path):
    srv = scripted_server([status(400), status(400), status(400), text(VALID_TEXT)])
    client = client_for(srv, tmp_path, cache=False)
    with pytest.raises(LLMItemError, match="HTTP 400"):
        client.complete(USER, schema=Scenario)
    assert [r.get("response_format", {}).get("type") for r in srv.requests] == [
        "json_schema",
        "json_object",
        None,
    ]
    assert client.complete(USER, schema=Scenario).room == "kitchen"
    assert srv.requests[-1]["response_format"]["type"] == "json_schema"


def test_switches_to_max_completion_tokens_when_asked(scripted_server, tmp_path):
    msg = json.dumps(
        {"error": {"message": "Unsupported parameter: 'max_tokens'. Use 'max_completion_tokens' instead."}}
    )

    def responder(body):
        return status(400, msg) if "max_tokens" in body else text(VALID_TEXT)

    srv = scripted_server(responder)
    client = client_for(srv, tmp_path, cache=False)
    assert client.complete(USER, schema=Scenario, max_tokens=77).room == "kitchen"
    assert srv.requests[-1]["max_completion_tokens"] == 77
    assert srv.requests[-1]["response_format"]["type"] == "json_schema"


def test_client_pickles_into_spawn_workers_and_usage_adds_up(scripted_server, tmp_path):
    import multiprocessing as mp
    import pickle

    srv = scripted_server([text(VALID_TEXT, prompt_tokens=3, completion_tokens=2)])
    client = client_for(srv, tmp_path, api_key="sk-pickle-secret")
    clone = pickle.loads(pickle.dumps(client))
    assert clone.config == client.config and clone.usage.requests == 0
    with mp.get_context("spawn").Pool(2) as pool:
        rooms = pool.starmap(complete_in_child, [(client, 0, 2), (client, 2, 2)])
    assert rooms == [["kitchen"] * 2] * 2 and len(srv.requests) == 4
    assert complete_in_child(client, 0, 4) == ["kitchen"] * 4 and len(srv.requests) == 4  # their cache writes
    run = RunFolder.create(tmp_path / "run")
    for _ in range(3):
        record_usage(run, client.usage.model_copy(update={"requests": 1, "prompt_tokens": 3}))
    assert run.load_manifest().llm_usage.requests == 3


def test_shared_client_is_per_config_and_keeps_the_real_key(scripted_server, tmp_path):
    from anomalygen.llm import shared_client

    srv = scripted_server([text("pong")])
    a = shared_client(llm_config_for(srv, tmp_path, api_key="sk-one"))
    assert shared_client(llm_config_for(srv, tmp_path, api_key="sk-one")) is a
    b = shared_client(llm_config_for(srv, tmp_path, api_key="sk-two"))
    assert b is not a
    b.complete(USER, cache=False)
    assert srv.headers[-1]["authorization"] == "Bearer sk-two"


def test_key_from_environment_is_scrubbed_too(scripted_server, tmp_path, monkeypatch):
    secret = "sk-from-env-987654321"
    monkeypatch.setenv("OPENAI_API_KEY", secret)
    srv = scripted_server([status(403, json.dumps({"error": {"message": f"key {secret} is blocked"}}))])
    client = client_for(srv, tmp_path, api_key=None)
    with pytest.raises(LLMItemError) as info:
        client.complete(USER)
    assert srv.headers[0]["authorization"] == f"Bearer {secret}"
    assert secret not in str(info.value) and "HTTP 403" in str(info.value)


def test_unreachable_endpoint_is_retried_then_an_item_error(tmp_path):
    from support.openai_server import ScriptedOpenAIServer

    with ScriptedOpenAIServer([text("x")]) as srv:
        pass  # now nothing listens on its port
    client = client_for(srv, tmp_path, http_retries=2, timeout_s=2.0)
    with pytest.raises(LLMItemError, match=r"after 3 attempt\(s\): cannot connect to http://127.0.0.1:\d+"):
        client.complete(USER)
    assert client.usage.retries == 2 and client.usage.requests == 0
