"""The offline engine through the CLI: 111 unique, buildable proposals, reproducible, with provenance.

Its speed is a benchmark figure (docs/benchmarks.md), not a timed assertion: a wall-clock limit fails
under load on shared machines and says nothing about behaviour."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from anomalygen.brainstorm.validate import proposal_problems
from anomalygen.knowledge import load_kb
from anomalygen.runfolder import read_jsonl
from anomalygen.schema import TaskProposal
from support.ids import assert_ids_carry_no_task_words


def _brainstorm(out, *extra):
    from anomalygen.cli import app

    return CliRunner().invoke(app, ["brainstorm", "--engine", "knowledge", "--seed", "0", "--out", str(out), "-q", *extra])


@pytest.fixture(scope="module")
def run111(tmp_path_factory):
    out = tmp_path_factory.mktemp("bs") / "x"
    result = _brainstorm(out, "--n", "111")
    assert result.exit_code == 0, result.output
    return out


def test_111_unique_valid_covering_proposals(run111):
    out = run111
    tasks = read_jsonl(out / "tasks.jsonl", TaskProposal)
    kb = load_kb()
    assert len(tasks) == 111
    assert len({t.id for t in tasks}) == 111
    assert len({t.name.lower() for t in tasks}) == 111
    sc = [(t.hazard_class, t.scenario.hazard_object, t.scenario.placement, t.scenario.room, t.scenario.person_at_risk) for t in tasks]
    assert len(set(sc)) == 111
    assert all(t.id.startswith(f"t{i:04d}-") for i, t in enumerate(tasks, start=1))
    assert_ids_carry_no_task_words(tasks)
    assert [p for t in tasks for p in proposal_problems(t, kb)] == []
    assert {t.category.value for t in tasks} == {"household_hazard", "hygiene", "child_safety"}
    paper = {t.hazard_class for t in tasks if kb.hazard_classes[t.hazard_class].paper_class}
    assert len(paper) >= 10
    for t in tasks:  # valid by construction: the hazard object can be the class's hazard
        hc = kb.hazard_classes[t.hazard_class]
        assert t.scenario.hazard_object in kb.hazard_candidates(hc)
        assert t.scenario.placement in hc.placements
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["stages"]["brainstorm"]["done"] == 111


def test_same_seed_gives_identical_file(tmp_path):
    first, second, other = tmp_path / "a", tmp_path / "b", tmp_path / "c"
    assert _brainstorm(first, "--n", "12").exit_code == 0
    assert _brainstorm(second, "--n", "12").exit_code == 0
    assert (first / "tasks.jsonl").read_bytes() == (second / "tasks.jsonl").read_bytes()
    assert _brainstorm(other, "--n", "12", "--seed", "1").exit_code == 0
    assert (other / "tasks.jsonl").read_bytes() != (first / "tasks.jsonl").read_bytes()


def test_later_rounds_cite_other_agents_previous_round(run111):
    out = run111
    tasks = {t.id: t for t in read_jsonl(out / "tasks.jsonl", TaskProposal)}
    later = [t for t in tasks.values() if t.provenance.round >= 2]
    assert len(later) >= 60
    citing = [t for t in later if t.provenance.builds_on]
    assert len(citing) >= 0.9 * len(later)
    for t in citing:
        assert t.provenance.borrowed and set(t.provenance.borrowed) <= {"mechanism", "location", "co_objects", "person_at_risk"}
        for src_id in t.provenance.builds_on:
            src = tasks[src_id]
            assert src.provenance.round == t.provenance.round - 1
            assert src.provenance.agent_role != t.provenance.agent_role or src.provenance.agent_role is None
    # a borrowed location really is the source's room or placement
    for t in citing:
        if t.provenance.borrowed == ["location"]:
            src = tasks[t.provenance.builds_on[0]]
            assert src.scenario.room == t.scenario.room or src.scenario.placement == t.scenario.placement


def test_existing_tasks_are_kept_unless_forced(run111, tmp_path):
    out = run111
    before = (out / "tasks.jsonl").read_bytes()
    result = _brainstorm(out, "--n", "111", "--json")
    assert result.exit_code == 0
    assert json.loads(result.stdout)["skipped"] == 111
    assert (out / "tasks.jsonl").read_bytes() == before


def test_scenarios_cover_the_composed_space(run111):
    """Diversity is counted where it matters (issue 39): at seed 0, at least 105 of 111 tasks are distinct
    (class, object at fault, placement, room) scenarios, and no room holds more than 30 % of them."""
    import collections

    tasks = read_jsonl(run111 / "tasks.jsonl", TaskProposal)
    keys = {(t.hazard_class, t.scenario.hazard_object, t.scenario.placement, t.scenario.room) for t in tasks}
    assert len(keys) >= 105
    rooms = collections.Counter(t.scenario.room for t in tasks)
    assert max(rooms.values()) <= 0.30 * len(tasks), rooms


def test_bring_your_own_tasks(run111, tmp_path):
    out = run111
    lines = (out / "tasks.jsonl").read_text().splitlines()[:3]
    good = tmp_path / "mine.jsonl"
    good.write_text("\n".join(lines) + "\n")
    dest = tmp_path / "byo"
    result = _brainstorm(dest, "--tasks", str(good))
    assert result.exit_code == 0, result.output
    assert len(read_jsonl(dest / "tasks.jsonl", TaskProposal)) == 3

    bad_obj = json.loads(lines[1])
    bad_obj["scenario"]["hazard_object"] = "flux_capacitor"
    broken = tmp_path / "broken.jsonl"
    broken.write_text("\n".join([lines[0], json.dumps(bad_obj), '{"id": "x"}']) + "\n")
    from anomalygen.brainstorm.stage import load_user_tasks
    from anomalygen.errors import UserError

    with pytest.raises(UserError, match="line 3"):
        load_user_tasks(broken)
    broken.write_text("\n".join([lines[0], json.dumps(bad_obj)]) + "\n")
    with pytest.raises(UserError, match="line 2 .*flux_capacitor"):
        load_user_tasks(broken)


def test_texts_are_well_formed(run111):
    """Names stay short; a description is the situation, the danger, who is at risk and the fix (3-6
    plain sentences), and it names the object at fault and the room. There is no Self-BLEU target for
    the offline engine (issue 39): the text says the task, it does not buy a metric."""
    import re

    from anomalygen.brainstorm.realise import nice, room_words

    def room_names(room: str) -> list[str]:
        return [room_words(room)]

    out = run111
    tasks = read_jsonl(out / "tasks.jsonl", TaskProposal)
    for t in tasks:
        assert 3 <= len(t.name.split()) <= 8, t.name
        sentences = [s for s in re.split(r"(?<=[.!?])\s+", t.description) if s]
        assert 3 <= len(sentences) <= 6, t.description
        assert "{" not in t.description and "[" not in t.description and "  " not in t.description
        text = f"{t.name} {t.description}".lower()
        assert nice(t.scenario.hazard_object).lower() in text, text
        assert any(r in text for r in room_names(t.scenario.room)), text


def test_a_run_over_a_few_targets_returns_every_task_asked():
    """A fridge, a toaster and a stove compose few scenes; the rest repeat one for another person at
    risk (its words nearly the same by design, so the novelty filter stands aside) rather than fall
    short, and the room cap (for the open catalogue) does not starve a run the targets tie to a kitchen."""
    from anomalygen.brainstorm.knowledge_engine import KnowledgeEngine

    tasks = KnowledgeEngine(seed=0, targets=["Refrigerator", "Toaster", "Stove"]).run(20)
    assert len(tasks) == 20 and len({t.id for t in tasks}) == 20
