"""LLM group brainstorming against the scripted OpenAI-compatible server (real HTTP on 127.0.0.1)."""

from __future__ import annotations

import json
import re
import threading

import pytest

from anomalygen.brainstorm.llm_engine import LLMEngine, reply_json
from anomalygen.knowledge import load_kb
from anomalygen.llm import get_client
from support.fixtures import llm_config_for
from support.openai_server import text


def _proposal(name: str, **over) -> dict:
    base = {
        "name": name,
        "explanation": "Tablets within reach of a toddler can poison them.",
        "description": f"{name}: a blister pack lies on the low coffee table in the living room.",
        "hazard_class": "secure_medications",
        "category": "child_safety",
        "target_asset": "Safe",
        "hazard_object": "blister_pack",
        "room": "living_room",
        "placement": "low_table",
        "person_at_risk": "a toddler",
        "container": "medicine_cabinet",
        "co_objects": ["book"],
        "solution": "Put the blister pack in the medicine cabinet.",
        "success_condition": "The blister pack is inside the medicine cabinet.",
    }
    base.update(over)
    return base


def _role_of(body) -> str:
    system = body["messages"][0]["content"]
    m = re.search(r"You are the (.+?) of a household", system)
    return m.group(1) if m else "plain"


def _round_of(body) -> int:
    user = [m for m in body["messages"] if m["role"] == "user"][0]["content"]
    return int(re.search(r"Round (\d+)", user).group(1))


class Responder:
    """Answers every agent with a uniquely named proposal, citing the ids it was shown."""

    def __init__(self, bad_first: bool = False):
        self.lock = threading.Lock()
        self.bad_first = bad_first
        self.count = 0

    def __call__(self, body):
        role, r = _role_of(body), _round_of(body)
        user = [m for m in body["messages"] if m["role"] == "user"][0]["content"]
        shown = re.findall(r"\[(t\d{4}-[a-z0-9-]+)\]", user)
        with self.lock:
            self.count += 1
            k = self.count
        if self.bad_first and r == 1 and len(body["messages"]) == 2:
            return text(reply_json(_proposal(f"{role} idea round {r}", hazard_object="flux_capacitor")))
        return text(reply_json(_proposal(f"{role} idea round {r} number {k}", builds_on=shown[:1], borrowed=["location"] if shown else [])))


def _engine(cfg, **kw) -> LLMEngine:
    return LLMEngine(client=get_client(cfg), kb=load_kb(), **kw)


def test_each_agent_sees_the_other_agents_previous_round(scripted_server, tmp_path):
    srv = scripted_server(Responder())
    engine = _engine(llm_config_for(srv, tmp_path, cache=False), agents=3, rounds=3)
    tasks = engine.run(9)
    assert len(tasks) == 9 and not engine.errors
    by_round: dict[int, dict[str, str]] = {}
    for t in tasks:
        by_round.setdefault(t.provenance.round, {})[t.provenance.agent_role] = t.name
    assert sorted(by_round) == [1, 2, 3] and all(len(v) == 3 for v in by_round.values())
    kb = load_kb()
    role_names = {kb.roles[r].name: r for r in kb.roles}
    prompts = [(role_names[_role_of(b)], _round_of(b), [m for m in b["messages"] if m["role"] == "user"][0]["content"]) for b in srv.requests]
    later = [p for p in prompts if p[1] >= 2]
    assert len(later) == 6
    for role, r, user in later:
        for other_role, name in by_round[r - 1].items():
            if other_role == role:
                assert name not in user  # its own idea is not listed back to it
            else:
                assert name in user
        assert "collaborative" in [b for b in srv.requests if _round_of(b) == r and role_names[_role_of(b)] == role][0]["messages"][0]["content"]
    for t in tasks:
        if t.provenance.round >= 2:
            assert t.provenance.builds_on and t.provenance.builds_on[0] in {x.id for x in tasks if x.provenance.round == t.provenance.round - 1}
    system = srv.requests[0]["messages"][0]["content"]
    assert "suction gripper" in system and "cannot clean" in system


def test_unknown_object_triggers_repair(scripted_server, tmp_path):
    srv = scripted_server(Responder(bad_first=True))
    engine = _engine(llm_config_for(srv, tmp_path, cache=False), agents=2, rounds=1)
    tasks = engine.run(2)
    assert len(tasks) == 2 and not engine.errors
    repairs = [b for b in srv.requests if len(b["messages"]) > 2]
    assert len(repairs) == 2
    assert any("flux_capacitor" in m["content"] for b in repairs for m in b["messages"] if m["role"] == "user")


def test_one_failing_agent_does_not_end_the_batch(scripted_server, tmp_path):
    def responder(body):
        if _role_of(body) == "Engineer":
            return text("this is not json at all")
        return Responder()(body)

    srv = scripted_server(responder)
    engine = _engine(llm_config_for(srv, tmp_path, cache=False, repair_retries=1), agents=3, rounds=1)
    tasks = engine.run(3)
    assert len(tasks) == 2
    assert list(engine.errors) == ["r1-agent1"]


def test_llm_stage_writes_tasks_and_usage(scripted_server, tmp_path):
    from anomalygen.brainstorm.stage import run_stage
    from anomalygen.config import Settings
    from anomalygen.runfolder import RunFolder, read_jsonl
    from anomalygen.schema import TaskProposal

    srv = scripted_server(Responder())
    settings = Settings(quiet=True, llm=llm_config_for(srv, tmp_path, cache=False), brainstorm={"engine": "llm", "n": 4, "agents": 2, "rounds": 2})
    run = RunFolder.create(tmp_path / "run", settings=settings)
    summary = run_stage(run, settings)
    assert summary.done == 4 and summary.failed == 0
    assert len(read_jsonl(run.tasks_path, TaskProposal)) == 4
    manifest = json.loads(run.manifest_path.read_text())
    assert manifest["llm_usage"]["requests"] == len(srv.requests) == 4


@pytest.mark.slow
@pytest.mark.gguf
def test_tiny_gguf_mechanics(tmp_path):
    from anomalygen.brainstorm.stage import run_stage
    from anomalygen.config import Settings
    from anomalygen.runfolder import RunFolder

    settings = Settings(
        quiet=True,
        llm={"backend": "llamacpp", "cache_path": str(tmp_path / "c.sqlite"), "repair_retries": 0, "max_tokens": 96},
        brainstorm={"engine": "llm", "n": 1, "agents": 1, "rounds": 1},
    )
    run = RunFolder.create(tmp_path / "run", settings=settings)
    summary = run_stage(run, settings)
    # The 135M model seldom names real catalogue objects: ending as per-item errors is accepted, but
    # the round must have run and the file must be well-formed either way.
    from anomalygen.runfolder import read_jsonl
    from anomalygen.schema import TaskProposal

    tasks = read_jsonl(run.tasks_path, TaskProposal)
    assert summary.done == len(tasks) <= 1
    if not tasks:
        assert summary.failed >= 1 and run.errors("brainstorm")
    for task in tasks:  # a proposal that survived was grounded, and says how
        assert {"hazard_class", "target_asset", "scenario.hazard_object"} <= {m.field for m in task.grounding}
    manifest = json.loads(run.manifest_path.read_text())
    assert manifest["llm_usage"]["requests"] >= 1


def test_llm_ablation_modes(scripted_server, tmp_path):
    srv = scripted_server(Responder())
    cfg = llm_config_for(srv, tmp_path, cache=False)
    plain = _engine(cfg, agents=4, rounds=3, mode="plain").run(2)
    assert [t.provenance.agent_role for t in plain] == [None, None]  # one role-less request per proposal
    assert len(srv.requests) == 2 and all("Propose one hazard scenario" in b["messages"][-1]["content"] for b in srv.requests)
    assert "You are the" not in srv.requests[-1]["messages"][0]["content"]
    srv.requests.clear()
    roleplay = _engine(cfg, agents=3, rounds=3, mode="roleplay").run(3)
    assert {t.provenance.round for t in roleplay} == {1}
    assert len({t.provenance.agent_role for t in roleplay}) == 3 and len(srv.requests) == 3
