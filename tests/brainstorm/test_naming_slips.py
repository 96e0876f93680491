"""Issue 15: the naming slips a real 1.5B model made are grounded, not rejected.

A scripted OpenAI-compatible server replays the exact slips measured with the real model ("kettle",
"cabinet", "kitchen", "household_hazard", "other" without text); each proposal must come out valid
with the intended catalogue object and a recorded grounding, without a single repair request.
"""

from __future__ import annotations

import json
import threading

from anomalygen.brainstorm.llm_engine import LLMEngine, reply_json
from anomalygen.brainstorm.llm_reply import LLMProposal
from anomalygen.knowledge import load_kb
from anomalygen.llm import get_client
from anomalygen.llm.schema_tools import reply_token_budget
from anomalygen.schema import Placement
from support.fixtures import llm_config_for
from support.openai_server import text

BASE = {
    "explanation": "Someone could get hurt.",
    "category": "household_hazard",
    "room": "kitchen",
    "placement": "counter",
    "person_at_risk": "an adult",
    "co_objects": [],
    "solution": "The robot fixes it.",
    "success_condition": "It is safe.",
}

#: (reply fields, field -> expected grounded value)
SLIPS = [
    (
        {"name": "Kettle left boiling", "description": "An electric kettle keeps boiling on the counter while nobody is home.",
         "hazard_class": "switch_off_appliance", "target_asset": "kettle", "hazard_object": "kettle"},
        {"target_asset": "Kettle", "scenario.hazard_object": "Kettle", "hazard_class": "switch_off_appliance"},
    ),
    (
        {"name": "Bleach on the counter", "description": "An open jug of bleach stands on the counter next to food.",
         "hazard_class": "manage_chemical_risks", "target_asset": "Bottle", "hazard_object": "bleach_bottle", "container": "cabinet"},
        {"scenario.container": "StorageFurniture", "scenario.hazard_object": "bleach_bottle"},
    ),
    (
        {"name": "Knife among the plates", "description": "A sharp kitchen knife lies on the counter among the clean plates.",
         "hazard_class": "store_sharp_objects", "target_asset": "Knife", "hazard_object": "kitchen_knife", "container": "StorageFurniture",
         "co_objects": ["kitchen", "plate"]},
        {"scenario.hazard_object": "kitchen_knife", "scenario.co_objects": ["plate"]},
    ),
    (
        {"name": "Toaster still glowing", "description": "The toaster was left switched on and keeps heating with nobody in the kitchen.",
         "hazard_class": "household_hazard", "target_asset": "Toaster", "hazard_object": "Toaster"},
        {"hazard_class": "switch_off_appliance", "scenario.hazard_object": "Toaster"},
    ),
    (
        {"name": "Pills on the coffee table", "description": "A blister pack of pills lies on the low coffee table where a toddler plays.",
         "explanation": "A toddler could swallow the tablets.", "category": "child_safety", "hazard_class": "other",
         "target_asset": "Safe", "hazard_object": "blister pack", "room": "living room", "placement": "coffee table", "container": "medicine cabinet"},
        {"hazard_class": "secure_medications", "scenario.hazard_object": "blister_pack", "scenario.room": "living_room",
         "scenario.placement": Placement(relation="on", support="low_table"), "scenario.container": "medicine_cabinet"},
    ),
]


def _reply(fields: dict) -> dict:
    return {**BASE, **fields}


class Replay:
    """Answers the k-th first request with the k-th slip (requests may arrive in any order)."""

    def __init__(self):
        self.lock = threading.Lock()
        self.by_prompt: dict[str, int] = {}

    def __call__(self, body):
        key = json.dumps(body["messages"])
        with self.lock:
            k = self.by_prompt.setdefault(key, len(self.by_prompt))
        return text(reply_json(_reply(SLIPS[k % len(SLIPS)][0])))


def _value(task, field: str):
    obj = task
    for part in field.split("."):
        obj = getattr(obj, part)
    return obj


def test_measured_naming_slips_are_grounded_without_repair(scripted_server, tmp_path):
    srv = scripted_server(Replay())
    engine = LLMEngine(client=get_client(llm_config_for(srv, tmp_path, cache=False)), kb=load_kb(), agents=5, rounds=1, mode="roleplay")
    tasks = engine.run(len(SLIPS))
    assert not engine.errors and len(tasks) == len(SLIPS)
    assert len(srv.requests) == len(SLIPS)  # no repair round was needed
    by_name = {t.name: t for t in tasks}
    for fields, expected in SLIPS:
        task = by_name[fields["name"]]
        for field, want in expected.items():
            assert _value(task, field) == want, (fields["name"], field)
        recorded = {m.field: m for m in task.grounding}
        assert recorded["target_asset"].grounded == task.target_asset
        assert recorded["hazard_class"].grounded == task.hazard_class
    kettle = by_name["Kettle left boiling"]
    assert {m.written: m.method for m in kettle.grounding}["kettle"] == "normalised"
    toaster = by_name["Toaster still glowing"].grounding
    assert next(m for m in toaster if m.field == "hazard_class").method == "composed"  # from its own text, not retrieval
    knife = by_name["Knife among the plates"].grounding
    assert any(m.written == "kitchen" and m.method == "dropped" for m in knife)


def test_one_proposal_per_request_with_a_schema_sized_budget(scripted_server, tmp_path):
    srv = scripted_server(Replay())
    engine = LLMEngine(client=get_client(llm_config_for(srv, tmp_path, cache=False)), kb=load_kb(), agents=1, rounds=1, mode="plain")
    engine.run(3)
    assert len(srv.requests) == 3
    budget = reply_token_budget(LLMProposal)
    assert all(b["max_tokens"] == budget for b in srv.requests)
    assert 256 <= budget <= 2048


def test_a_truncated_reply_is_recorded_not_dropped(scripted_server, tmp_path):
    budget = reply_token_budget(LLMProposal)
    cut = json.dumps(_reply(SLIPS[0][0]))[:120]
    srv = scripted_server([text(cut, completion_tokens=budget)])
    client = get_client(llm_config_for(srv, tmp_path, cache=False, repair_retries=0))
    engine = LLMEngine(client=client, kb=load_kb(), agents=1, rounds=1, mode="plain")
    assert engine.run(1) == []
    assert "truncated at max_tokens" in engine.errors["r1-agent0"]
    assert client.reset_usage().truncated == 1


def test_a_hazard_that_fits_no_class_becomes_other_with_the_models_words(scripted_server, tmp_path):
    wobbly = _reply({"name": "Wobbly chair leg", "description": "One leg of a dining chair has come loose and wobbles.",
                     "explanation": "The loose leg of the chair may snap when someone sits down.", "hazard_class": "furniture_damage",
                     "target_asset": "Chair", "hazard_object": "Chair", "placement": "floor"})
    srv = scripted_server([text(reply_json(wobbly))])
    engine = LLMEngine(client=get_client(llm_config_for(srv, tmp_path, cache=False)), kb=load_kb(), agents=1, rounds=1, mode="plain")
    [task] = engine.run(1)
    assert task.hazard_class == "other" and task.hazard_other == wobbly["explanation"]
    assert next(m for m in task.grounding if m.field == "hazard_class").method == "other"
