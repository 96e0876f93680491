"""``brainstorm --tasks-text``: plain descriptions grounded into buildable tasks (issue 15).

The fixture holds 20 descriptions written for this test, one per hazard class we support, with the
class and hazard object each is meant to become. Offline grounding (mentions and Sentence-BERT
retrieval, no model) must get at least 18 of them right, and every task it writes must pass the same
catalogue checks as a user's tasks.jsonl.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from anomalygen.brainstorm.llm_engine import reply_json
from anomalygen.brainstorm.validate import proposal_problems
from anomalygen.knowledge import load_kb
from anomalygen.runfolder import read_jsonl
from anomalygen.schema import Placement, TaskProposal
from support.fixtures import llm_config_for
from support.ids import assert_ids_carry_no_task_words
from support.openai_server import text

FIXTURES = Path(__file__).parent / "fixtures"
LINES = FIXTURES / "free_text_tasks.txt"


def test_cli_grounds_plain_descriptions_offline(tmp_path):
    run = tmp_path / "run"
    env = {**os.environ, "ANOMALYGEN_CACHE_DIR": str(tmp_path / "cache")}
    result = subprocess.run(
        [sys.executable, "-m", "anomalygen.cli", "brainstorm", "--run", str(run), "--engine", "knowledge",
         "--tasks-text", str(LINES), "--quiet"],
        capture_output=True, text=True, env=env, timeout=300,
    )
    assert result.returncode == 0, result.stderr
    tasks = read_jsonl(run / "tasks.jsonl", TaskProposal)
    lines = LINES.read_text().splitlines()
    expected = json.loads((FIXTURES / "free_text_expected.json").read_text())
    assert len(tasks) == len(lines) == len(expected) == 20
    hits = sum(t.hazard_class == c and t.scenario.hazard_object == h for t, (c, h) in zip(tasks, expected, strict=True))
    assert hits >= 18, hits
    kb = load_kb()
    for task, line in zip(tasks, lines, strict=True):
        assert task.description == line  # the person's words are kept
        assert not proposal_problems(task, kb)
        assert {m.field for m in task.grounding} >= {"hazard_class", "scenario.hazard_object", "target_asset"}
    assert_ids_carry_no_task_words(tasks)


def test_tasks_text_with_the_llm_engine_grounds_the_models_names(scripted_server, tmp_path):
    from anomalygen.brainstorm.stage import run_stage
    from anomalygen.config import Settings
    from anomalygen.runfolder import RunFolder

    reply = {
        "name": "Kettle left on", "explanation": "It may boil dry.", "description": "model text",
        "hazard_class": "household_hazard", "category": "household_hazard", "target_asset": "kettle",
        "hazard_object": "kettle", "room": "Kitchen", "placement": "kitchen counter", "co_objects": ["kitchen"],
    }
    srv = scripted_server([text(reply_json(reply))])
    lines = tmp_path / "tasks.txt"
    lines.write_text("The kettle was left switched on and is boiling away.\n")
    settings = Settings(quiet=True, llm=llm_config_for(srv, tmp_path, cache=False), brainstorm={"engine": "llm", "tasks_text": str(lines)})
    run = RunFolder.create(tmp_path / "run", settings=settings)
    summary = run_stage(run, settings)
    assert summary.done == 1 and summary.failed == 0
    [task] = read_jsonl(run.tasks_path, TaskProposal)
    assert (task.target_asset, task.scenario.hazard_object, task.hazard_class) == ("Kettle", "Kettle", "switch_off_appliance")
    assert (task.scenario.room, task.scenario.placement) == ("kitchen", Placement(relation="on", support="counter"))
    assert task.description == "The kettle was left switched on and is boiling away."
    assert_ids_carry_no_task_words([task])
    assert "boiling away" in srv.requests[0]["messages"][-1]["content"]
