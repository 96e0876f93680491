"""A drawn asset must be able to show the states its task asks of it, or give way to another draw."""

from __future__ import annotations

from anomalygen.assets.core import generate
from anomalygen.knowledge import load_kb
from anomalygen.scene.asset_choice import wanted_states
from anomalygen.schema import ObjectRole, TaskProposal
from anomalygen.world.states import why_cannot_show


def test_only_assets_that_can_show_a_state_pass():
    pan, pot, sink, iron = (generate(c, 0) for c in ("frying_pan", "Bucket", "Sink", "iron"))
    assert why_cannot_show(pan, "handle_out") is None
    assert "handle" in why_cannot_show(pot, "handle_out")
    assert why_cannot_show(sink, "contains_water") is None
    # a category that never can is left to the builder's refusal, which names what can
    assert why_cannot_show(iron, "contains_water") is None and why_cannot_show(pan, "face_down") is None
    assert why_cannot_show(iron, "face_down") is None
    assert why_cannot_show(pan, "on") is None  # read from controls: the part check asks for the switch


def test_the_states_wanted_are_the_tasks_and_for_the_object_at_fault_its_classs():
    kb = load_kb()
    hc = kb.hazard_classes["turn_pan_handle_inward"]
    task = TaskProposal.model_validate({
        "id": "t1", "name": "pan", "explanation": "e", "description": "d", "category": "household_hazard",
        "hazard_class": hc.id, "target_asset": "KitchenPot", "provenance": {"engine": "knowledge", "mode": "brainstorm"},
        "scenario": {"hazard_object": "frying_pan", "room": "kitchen", "placement": "counter_edge",
                     "states": {"Sink": ["contains_water"]}},
    })
    assert wanted_states(task, "frying_pan", hc, ObjectRole.HAZARD) == {"handle_out"}
    assert wanted_states(task, "frying_pan", hc, ObjectRole.CLUTTER) == set()
    assert wanted_states(task, "Sink", hc, ObjectRole.CONTAINER) == {"contains_water"}
