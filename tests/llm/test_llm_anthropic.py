"""The anthropic backend (official SDK) against the scripted server's Messages API endpoint."""

from __future__ import annotations

from llm_helpers import USER, VALID, VALID_TEXT

from anomalygen.llm import get_client
from anomalygen.schema import Scenario
from support.fixtures import llm_config_for
from support.openai_server import status, text, tool_use


def anthropic_client(srv, tmp_path, **kw):
    cfg = llm_config_for(srv, tmp_path, backend="anthropic", model="claude-test", **kw)
    return get_client(cfg, backoff_base_s=0.01)


def test_structured_output_through_forced_tool_use(scripted_server, tmp_path):
    srv = scripted_server([tool_use(VALID)])
    client = anthropic_client(srv, tmp_path)
    system = [{"role": "system", "content": "You are careful."}]
    result = client.complete(system + USER, schema=Scenario, temperature=0.3, max_tokens=200)
    assert result == Scenario(**VALID)
    assert srv.paths == ["/v1/messages"]
    body = srv.requests[0]
    assert body["tool_choice"] == {"type": "tool", "name": "emit_Scenario"}
    assert body["tools"][0]["input_schema"]["required"] == ["hazard_object", "room", "placement"]
    assert body["system"].startswith("You are careful.") and "JSON schema" in body["system"]
    assert [m["role"] for m in body["messages"]] == ["user"]
    assert (body["max_tokens"], body["model"]) == (200, "claude-test")
    assert body.get("temperature", 0.3) == 0.3  # sent where the installed SDK still accepts it
    h = srv.headers[0]
    assert "sk-test-not-a-real-key" in (
        h.get("x-api-key", ""),
        h.get("authorization", "").removeprefix("Bearer "),
    )
    assert (client.usage.prompt_tokens, client.usage.completion_tokens) == (11, 7)


def test_repair_retry_and_text_fallback(scripted_server, tmp_path):
    srv = scripted_server(
        [status(529), tool_use({"hazard_object": "knife", "room": 1}), text("ok: " + VALID_TEXT)]
    )
    client = anthropic_client(srv, tmp_path, http_retries=2)
    assert client.complete(USER, schema=Scenario).placement.key == "counter_edge"
    assert len(srv.requests) == 3
    repair_turn = srv.requests[2]["messages"]
    assert [m["role"] for m in repair_turn] == ["user", "assistant", "user"]
    assert "room: Input should be a valid string" in repair_turn[-1]["content"]
    assert "placement: Field required" in repair_turn[-1]["content"]
    assert client.usage.retries == 2  # one HTTP retry (529) and one repair


def test_plain_text_without_schema(scripted_server, tmp_path):
    srv = scripted_server([text("pong")])
    assert anthropic_client(srv, tmp_path).complete(USER) == "pong"
    assert "tools" not in srv.requests[0]
