"""The observation shows the scene as perceived and nothing about the task."""

from __future__ import annotations

import json
import re

import detect_graphs as g
import pytest

from anomalygen.detect.observation import joint_phrase, observation_json, observation_text


def _ngrams(text: str, n: int) -> set[tuple[str, ...]]:
    words = re.findall(r"[a-z0-9']+", text.lower())
    return {tuple(words[i : i + n]) for i in range(len(words) - n + 1)}


def assert_no_leak(text: str, task, n: int = 4) -> None:
    """No n-word phrase of the task's texts and no hazard-class id appear in the text.

    n = 4: on real scenes, 3-word overlaps are generic phrases both sides use ("from the edge").
    """
    lowered = text.lower()
    assert task.hazard_class not in lowered
    assert task.hazard_class.replace("_", " ") not in lowered
    for field in (task.name, task.description, task.solution, task.explanation):
        shared = _ngrams(field, n) & _ngrams(text, n)
        assert not shared, f"task phrase leaked into the observation: {shared}"


@pytest.mark.parametrize(
    ("graph_fn", "task"),
    [(g.knife_on_counter_edge, g.KNIFE_TASK), (g.pill_on_floor, g.PILL_TASK), (g.open_fridge, g.FRIDGE_TASK)],
)
def test_observation_never_contains_the_task(graph_fn, task):
    graph = graph_fn()
    assert_no_leak(observation_text(graph), task)
    assert_no_leak(json.dumps(observation_json(graph)), task)


def test_scene_id_is_not_shown():
    graph = g.knife_on_counter_edge().model_copy(update={"scene_id": "t-knife-store_sharp_objects"})
    assert "store_sharp" not in observation_text(graph)
    assert "scene" not in observation_json(graph)


def test_text_states_what_matters_for_hazards():
    text = observation_text(g.knife_on_counter_edge())
    knife_line = next(line for line in text.splitlines() if line.startswith("- kitchen_knife_0"))
    assert "(kitchen_knife [sharp])" in knife_line
    assert "0.90 m above the floor" in knife_line
    assert "near the edge, 0.04 m from the edge" in knife_line
    assert "within a small child's reach" in knife_line
    assert "kitchen_knife_0 is on counter_0" in text
    pill = next(line for line in observation_text(g.pill_on_floor()).splitlines() if "pill_bottle_0 (" in line)
    assert "on the floor" in pill and "medication" in pill


def test_joint_states_read_like_speech():
    text = observation_text(g.open_fridge())
    assert "door 80% open" in text
    assert "storage_0 (StorageFurniture [furniture, container])" in text and "door closed" in text
    knob = g.door("stove_knob", 0.7, label="knob")
    assert joint_phrase(knob) == "knob on"
    assert joint_phrase(g.door("k", 0.0, label="knob")) == "knob off"


def test_json_rendering_is_complete_and_compact():
    graph = g.two_hazards()
    data = observation_json(graph)
    assert [o["name"] for o in data["objects"]] == [o.name for o in graph.objects]
    knife = next(o for o in data["objects"] if o["name"] == "kitchen_knife_0")
    assert knife["near_edge"] is True and knife["distance_to_edge"] == 0.04 and knife["properties"] == ["sharp"]
    marble = next(o for o in data["objects"] if o["name"] == "marble_0")
    assert marble["on_floor"] is True and marble["child_reachable"] is True
    assert "kitchen_knife_0 is on counter_0" in data["relations"]


def test_clutter_is_kept_exactly_as_built():
    graph = g.add_clutter(g.knife_on_counter_edge(), 5)
    text = observation_text(graph)
    for o in graph.objects:
        assert f"- {o.name} ({o.category}" in text
    assert f"Objects ({len(graph.objects)})" in text
