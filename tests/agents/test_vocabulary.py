"""The skill vocabulary: calls read from text or dicts, checked against a scene, with reasons."""

import pytest

from anomalygen.agents.vocabulary import VOCABULARY, Call, CallError, SceneView, parse_call, validate_call
from anomalygen.knowledge import load_kb


def _obj(name, kind, movable=True, container=False, parts=()):
    return {"name": name, "kind": kind, "movable": int(movable), "container": int(container),
            "parts": [{"name": n, "label": lab, "state": ""} for n, lab in parts]}


VIEW = SceneView.from_objects([
    _obj("knife_0", "kitchen_knife"),
    _obj("drawer_0", "StorageFurniture", movable=False, container=True, parts=[("drawer_top", "drawer")]),
    _obj("table_0", "Table", movable=False),
    _obj("stove_0", "stove", movable=False, parts=[("knob_1", "knob"), ("knob_2", "knob")]),
    _obj("fridge_0", "Refrigerator", movable=False, container=True, parts=[("door_hinge", "door")]),
])
KB = load_kb()


def check(action):
    return validate_call(parse_call(action), VIEW, KB)


def test_text_and_structured_calls_read_the_same():
    a = check("pick_place(knife_0, drawer_0)")
    b = check({"skill": "pick_place", "args": {"object": "knife_0", "destination": "drawer_0"}})
    c = check({"skill": "pick_place", "object": "knife_0", "destination": "drawer_0"})
    d = check({"skill": "pick_place", "args": ["knife_0", "drawer_0"]})
    assert a == b == c == d
    assert a.args == {"object": "knife_0", "destination": "drawer_0", "how": "in"}  # the drawer has an inside
    assert check("pick_place(knife_0, table_0)").args["how"] == "on"
    assert check(" switch_off( stove_0, 'knob_2' ) ").args == {"object": "stove_0", "part": "knob_2"}
    assert check("close(fridge_0, door)").text() == "close(fridge_0, door)"
    assert check("done").skill == check("done()").skill == "done"
    assert check("wait(steps=40)").args == {"steps": 40.0}


def test_a_call_prints_as_it_is_written_and_reads_back():
    for text in ("pick_place(knife_0, drawer_0, how=in)", "move_away(knife_0, stove_0, distance=0.8)",
                 "fix(knife_0, store_sharp_objects, container=drawer_0)", "done"):
        call = check(text)
        assert check(call.text()) == call and str(call) == call.text()


@pytest.mark.parametrize("action, reason", [
    ("pick_place(spoon_9, drawer_0)", "'spoon_9' is not an object in the scene"),
    ("pick_place(knif_0, drawer_0)", "closest: knife_0"),
    ("pick_place(table_0, drawer_0)", "table_0 is fixed in place"),
    ("pick_place(knife_0, knife_0)", "the destination is the object itself"),
    ("pick_place(knife_0, table_0, how=in)", "table_0 has no inside"),
    ("pick_place(knife_0)", "pick_place needs destination"),
    ("pickplace(knife_0, drawer_0)", "did you mean pick_place?"),
    ("switch_off(knife_0)", "knife_0 has no knob, switch or tap"),
    ("switch_off(stove_0, knob_7)", "stove_0 has no part 'knob_7' (its parts: knob, knob_1, knob_2)"),
    ("close(table_0)", "table_0 has nothing that opens or closes"),
    ("move_away(knife_0, stove_0, distance=far)", "distance is a number"),
    ("wait(steps=100000)", "wait: steps is 1 to 500"),
    ("fix(knife_0, store_sharp_thing)", "no hazard class 'store_sharp_thing'"),
    ("fix(knife_0, store_sharp_objects, oven=stove_0)", "store_sharp_objects has no role oven"),
    ("close(fridge_0, door, colour=red)", "close takes no colour"),
    ("pick_place(knife_0, drawer_0, table_0, how=on)", "pick_place: how given twice"),
    ("pick_place(object=knife_0, drawer_0)", "a positional argument after a named one"),
    ("knife goes in the drawer please", "not a call"),
    (42, "not int"),
    ({"args": ["knife_0"]}, "needs 'skill'"),
])
def test_an_invalid_call_says_why(action, reason):
    with pytest.raises(CallError, match=None) as exc:
        check(action)
    assert reason in str(exc.value)


def test_every_skill_has_a_documented_signature():
    for name, spec in VOCABULARY.items():
        assert spec.doc and spec.signature().startswith(name)
    assert Call(skill="pick_place", args={"object": "a", "destination": "b"}).text() == "pick_place(a, b)"
