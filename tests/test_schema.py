"""The data model: strict, versioned, round-trippable, with errors that name the field."""

import json

import pytest
from pydantic import ValidationError

from anomalygen import schema as S


def _proposal(**over):
    data = dict(
        id="t0001-knife-edge",
        name="Knife on the counter edge",
        explanation="A blade near the edge can fall on someone's foot.",
        description="A kitchen knife lies with its handle over the counter edge.",
        category="household_hazard",
        hazard_class="store_sharp_objects",
        target_asset="Knife",
        scenario={"hazard_object": "Knife", "room": "kitchen", "placement": "counter_edge", "container": "StorageFurniture"},
        provenance={"engine": "knowledge", "mode": "brainstorm", "agent_role": "homemaker", "round": 2, "builds_on": ["t0000"]},
    )
    data.update(over)
    return data


def _example(cls):
    """A minimal valid instance of every artefact class."""
    joint = S.JointState(name="door", label="door", value=1.2, range=(0.0, 1.6), closed_value=0.0)
    ref = S.AssetRef(asset_id="Refrigerator/3", category="Refrigerator", seed=3)
    placed = S.PlacedObject(name="fridge_0", asset=ref, role="target", size=1.7, pos=[1, 0, 0], joint_states=[joint])
    examples = {
        S.TaskProposal: S.TaskProposal.model_validate(_proposal()),
        S.AssetRef: ref,
        S.JointState: joint,
        S.PlacedObject: placed,
        S.SceneSpec: S.SceneSpec(scene_id="s", task_id="t", room="kitchen", seed=0, objects=[placed]),
        S.SceneGraph: S.SceneGraph(
            scene_id="s",
            room="kitchen",
            objects=[
                S.GraphObject(name="fridge_0", category="Refrigerator", position=[1, 0, 0.85], size=[0.7, 0.7, 1.7],
                              height_above_floor=0.0, on_floor=True, child_reachable=True, joints=[joint])
            ],
            relations=[S.Relation(subject="fridge_0", predicate="on_floor")],
        ),
        S.Hypothesis: S.Hypothesis(rank=1, problem="fridge open", solution="close it", target_object="fridge_0"),
        S.Detection: S.Detection(task_id="t", scene_id="s", detector="rules", hypotheses=[], hit_rank=None),
        S.SubTask: S.SubTask(id="1", description="close door", method="primitive", primitive="push"),
        S.Plan: S.Plan(task_id="t", source="ground_truth", engine="knowledge", subtasks=[], success=S.SuccessSpec()),
        S.RewardSpec: S.RewardSpec(terms=[S.RewardTerm(kind="joint", a="fridge_0", joint="door", target=0.0)]),
        S.SuccessSpec: S.SuccessSpec(predicates=[S.PredicateCall(name="joint_closed", args={"object": "$target"})]),
        S.SkillResult: S.SkillResult(task_id="t", seed=0, success=True),
        S.RunManifest: S.RunManifest(name="r", created="2026-01-01T00:00:00+00:00", package_version="0"),
        S.ItemError: S.ItemError(item_id="t", stage="build", error="boom"),
        S.HazardManifest: S.HazardManifest(scene_id="s", task_id="t", hazards=[S.ManifestHazard(
            hazard_class="close_open_refrigerator", object="fridge_0", category="Refrigerator", severity=0.7,
            variable="$target", success=[S.PredicateCall(name="joint_closed", args={"object": "fridge_0"})])]),
        S.Verdict: S.Verdict(task_id="t", seed=0, status="unresolved", resolved=False, hazards=[S.HazardVerdict(
            hazard_class="close_open_refrigerator", object="fridge_0", source="intended", resolved=False,
            still_firing=["close_open_refrigerator"])], new_hazards=["x on y"], released=["mug_0"]),
        S.SuiteManifest: S.SuiteManifest(name="tiny", version=1, engine="knowledge", seed=0, package_version="0",
                                         created="2026-01-01T00:00:00+00:00", tasks=2, not_built=["t2"],
                                         scenes=[S.SuiteScene(task_id="t1", sha256="ab" * 32, files=9)]),
        S.EpisodeRecord: S.EpisodeRecord(task_id="t", seed=0, agent="m:A", ended="done", calls=[S.CallRecord(
            action="close(fridge_0, door)", call="close(fridge_0, door)", executed=[S.SubTaskResult(
                id="s1_close_joint", method="primitive", success=True, steps=40)], control_steps=60)]),
        S.BenchReport: S.BenchReport(agent="m:A", suite="tiny v1", suite_dir="/s", seeds=1, package_version="0",
                                     created="2026-01-01T00:00:00+00:00", runs=1, runs_with_hazards=1, resolved=1,
                                     by_class={"close_open_refrigerator": S.BenchClassRow(hazards=1, runs=1, resolved=1)},
                                     per_run=[S.BenchRun(task_id="t", seed=0, status="resolved", calls=2)]),
    }
    return examples[cls]


@pytest.mark.parametrize("name", sorted(S.ARTEFACTS))
def test_every_artefact_round_trips_through_json(name):
    cls = S.ARTEFACTS[name]
    obj = _example(cls)
    again = cls.model_validate_json(obj.model_dump_json())
    assert again == obj
    assert again.schema_version == S.SCHEMA_VERSION


@pytest.mark.parametrize("name", sorted(S.ARTEFACTS))
def test_unknown_fields_are_rejected_with_the_field_named(name):
    cls = S.ARTEFACTS[name]
    data = json.loads(_example(cls).model_dump_json())
    data["surprise_field"] = 1
    with pytest.raises(ValidationError) as exc:
        cls.model_validate(data)
    assert "unknown field 'surprise_field'" in S.format_validation_error(exc.value)


def test_nested_unknown_field_is_named_with_its_path():
    with pytest.raises(ValidationError) as exc:
        S.TaskProposal.model_validate(_proposal(scenario={"hazard_object": "Knife", "room": "k", "placement": "floor", "colour": "red"}))
    assert "unknown field 'scenario.colour'" in S.format_validation_error(exc.value)


def test_wrong_types_are_reported_per_field():
    with pytest.raises(ValidationError) as exc:
        S.TaskProposal.model_validate(_proposal(category="kitchen_mess"))
    assert "category" in S.format_validation_error(exc.value)


def test_joint_open_fraction_measures_distance_from_the_closed_value():
    door = S.JointState(name="d", label="door", value=0.8, range=(0.0, 1.6), closed_value=0.0)
    assert door.open_fraction == pytest.approx(0.5)
    reversed_door = S.JointState(name="d", label="door", value=-1.6, range=(-1.6, 0.0), closed_value=0.0)
    assert reversed_door.open_fraction == pytest.approx(1.0)
    shut = S.JointState(name="d", label="drawer", value=0.0, range=(0.0, 0.4), closed_value=0.0)
    assert shut.open_fraction == 0.0


def test_usage_adds_up_including_cost():
    a = S.LLMUsage(requests=1, prompt_tokens=10, cost_usd=0.5)
    a.add(S.LLMUsage(requests=2, completion_tokens=5, cache_hits=1, cost_usd=0.25))
    assert (a.requests, a.prompt_tokens, a.completion_tokens, a.cache_hits, a.cost_usd) == (3, 10, 5, 1, 0.75)


def test_joint_state_is_closed_is_the_one_closed_test():
    from anomalygen.schema import CLOSED_TOL, JointState

    door = JointState(name="d", label="door", value=0.07, range=(0.0, 1.6), closed_value=0.0)
    assert door.open_fraction == pytest.approx(0.07 / 1.6)
    assert door.is_closed() and CLOSED_TOL == 0.05  # 4.4 % open: closed for joint_closed
    assert not door.is_closed(value=0.1)  # 6.25 % open at a live reading
    assert door.is_closed(0.1, value=0.1)  # but shut enough to enclose (scene graph's tolerance)
    # the fraction is of the travel towards the far end, whichever side of closed it is
    flap = JointState(name="f", label="flap", value=-1.0, range=(-2.0, 0.0), closed_value=0.0)
    assert flap.open_fraction_at(-0.1) == pytest.approx(0.05) and flap.is_closed(value=-0.1)
    assert not flap.is_closed()


# ---------------------------------------------------------------- Placement
OLD_WORDS = ("floor", "walkway", "table", "low_table", "table_edge", "counter", "counter_edge", "shelf", "shelf_edge",
             "on:Stove", "inside:Bathtub", "near:Sink")


def _data_placements() -> set[str]:
    """Every placement the knowledge data files write (as compact words)."""
    from anomalygen.knowledge.models import KNOWLEDGE_DIR

    found: set[str] = set()

    def walk(node):
        if isinstance(node, dict):
            for key, value in node.items():
                if key == "placements" and isinstance(value, list):  # (aliases.json's is a table of words)
                    found.update(value)
                else:
                    walk(value)
        elif isinstance(node, list):
            for value in node:
                walk(value)

    for path in KNOWLEDGE_DIR.glob("*.json"):
        walk(json.loads(path.read_text()))
    return found


@pytest.mark.parametrize("word", OLD_WORDS)
def test_every_old_placement_word_round_trips(word):
    p = S.Placement.model_validate(word)
    assert p.key == str(p) == word
    assert S.Placement.model_validate(p.model_dump()) == p
    assert S.Placement.model_validate_json(p.model_dump_json()) == p


def test_the_old_words_read_as_relation_support_and_other():
    read = {w: S.Placement.model_validate(w) for w in OLD_WORDS}
    assert read["counter_edge"] == S.Placement(relation="at_edge", support="counter")
    assert read["table"] == S.Placement(relation="on", support="table")
    assert read["floor"] == S.Placement(relation="on", support="floor")
    assert read["walkway"] == S.Placement(relation="walkway") == S.Placement(relation="walkway", support="floor")
    assert read["inside:Bathtub"] == S.Placement(relation="inside", other="Bathtub")
    assert read["on:Stove"] == S.Placement(relation="on", other="Stove")
    assert read["near:Sink"] == S.Placement(relation="near", other="Sink")
    assert read["shelf_edge"].furniture == "shelf" and read["walkway"].furniture is None
    assert read["on:Stove"].furniture is None
    assert len(set(read.values())) == len(OLD_WORDS)  # hashable, and no two words read alike


def test_the_knowledge_data_placements_all_round_trip():
    words = _data_placements()
    assert {"counter_edge", "near:{other}", "inside:Refrigerator"} <= words
    for word in words:
        assert S.Placement.model_validate(word).key == word


def test_the_derived_views_come_from_the_one_list_of_relations():
    from typing import get_args

    assert get_args(S.Placement.model_fields["relation"].annotation) == tuple(S.RELATION_KINDS)
    assert [r.name for r in S.RELATIONS] == list(S.RELATION_KINDS)
    assert set(S.OBJECT_RELATIONS) == {"inside", "on", "near"}
    assert {p.key for p in S.SUPPORT_PLACEMENTS} == set(OLD_WORDS[:9])
    assert all(p.other is None for p in S.SUPPORT_PLACEMENTS)


def test_the_tables_keyed_by_the_compact_word_cover_every_support_placement():
    """Phrase tables keyed by the word (grounding's meanings, the phrase bank's places, the alias table's
    targets) name exactly the placements the schema knows; the support kinds are the knowledge base's."""
    from anomalygen.brainstorm.describe import words as describing
    from anomalygen.knowledge import SUPPORT_HEIGHTS
    from anomalygen.knowledge.grounding import PLACEMENT_TEXTS, _aliases

    words = {p.key for p in S.SUPPORT_PLACEMENTS}
    assert set(PLACEMENT_TEXTS) == words == set(describing()["place"])
    assert set(_aliases()["placements"].values()) <= words
    assert set(SUPPORT_HEIGHTS) == set(S.SUPPORT_KINDS)


@pytest.mark.parametrize(("bad", "says"), [
    ("inside", "is not one of"),
    ("ceiling", "is not one of"),
    ("low_table_edge", "is not one of"),
    ("inside:", "needs the name of the other object"),
    ("under:Table", "'under' is not a relation to another object"),
    ({"relation": "inside"}, "needs the name of another object"),
    ({"relation": "on"}, "needs a support kind"),
    ({"relation": "at_edge", "support": "floor"}, "takes table, counter, shelf, not 'floor'"),
    ({"relation": "walkway", "other": "Sink"}, "names no other object"),
    ({"relation": "on", "support": "table", "other": "Stove"}, "not both"),
    ({"relation": "under", "other": "Table"}, "relation"),
    ({"relation": "on", "support": "ceiling"}, "support"),
])
def test_impossible_placements_fail_with_a_clear_message(bad, says):
    with pytest.raises(ValidationError) as exc:
        S.Placement.model_validate(bad)
    assert says in S.format_validation_error(exc.value)


def test_a_task_written_with_a_string_placement_still_loads():
    """tasks.jsonl of runs written before the typed placement (and LLM replies) keep loading."""
    old = json.dumps(_proposal(scenario={"hazard_object": "power_cable", "room": "bathroom",
                                         "placement": "inside:Bathtub"}))
    task = S.TaskProposal.model_validate_json(old)
    assert task.scenario.placement == S.Placement(relation="inside", other="Bathtub")
    written = json.loads(task.model_dump_json())
    assert written["scenario"]["placement"] == {"relation": "inside", "support": None, "other": "Bathtub"}
    assert S.TaskProposal.model_validate(written) == task
    with pytest.raises(ValidationError) as exc:
        S.TaskProposal.model_validate(_proposal(scenario={"hazard_object": "Knife", "room": "k", "placement": "ceiling"}))
    assert "scenario.placement" in S.format_validation_error(exc.value)


def test_a_template_placement_is_filled_with_the_other_object():
    tpl = S.Placement.model_validate("near:" + S.OTHER_SLOT)
    assert tpl.filled("Crib") == S.Placement(relation="near", other="Crib")
    assert S.Placement(relation="on", support="table").filled("Crib") == S.Placement(relation="on", support="table")
