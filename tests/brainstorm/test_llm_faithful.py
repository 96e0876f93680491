"""The LLM path says what the text says (issue 25): category words, empty values and look-alike objects
are never grounded into something else, the user's line stays the description, and a hazard no class
covers may come back as a new class in the predicate language, checked against the vocabulary."""

from __future__ import annotations

from anomalygen.brainstorm.llm_engine import LLMEngine, reply_json
from anomalygen.knowledge import load_kb
from anomalygen.llm import get_client
from support.fixtures import llm_config_for
from support.openai_server import text

BASE = {
    "name": "A hazard", "explanation": "Someone could get hurt.", "description": "Something is wrong.",
    "hazard_class": "secure_medications", "category": "child_safety", "target_asset": "Safe",
    "hazard_object": "pill_bottle", "room": "living_room", "placement": "low_table", "person_at_risk": "a toddler",
    "container": "medicine_cabinet", "co_objects": [], "solution": "", "success_condition": "",
}


def _engine(srv, tmp_path, **kw) -> LLMEngine:
    cfg = llm_config_for(srv, tmp_path, cache=False, **kw)
    return LLMEngine(client=get_client(cfg), kb=load_kb(), agents=1, rounds=1, mode="plain")


def test_a_category_word_is_composed_from_the_text_or_goes_back_to_the_model(scripted_server, tmp_path):
    stated = {**BASE, "name": "Pills out", "hazard_class": "household_hazard",
              "description": "A pill bottle was left on the low coffee table where the toddler plays."}
    vague = {**BASE, "name": "Something off", "hazard_class": "household_hazard", "description": "Things look unsafe."}
    replies = {"Pills out": stated}

    def answer(body):  # each first request gets its own proposal; every repair of the vague one stays vague
        user = body["messages"][1]["content"]
        return text(reply_json(stated if "idea 1 of 2" in user and len(body["messages"]) == 2 else vague))

    srv = scripted_server(answer)
    del replies
    engine = _engine(srv, tmp_path, repair_retries=2)
    tasks = engine.run(2)
    assert [t.hazard_class for t in tasks] == ["secure_medications"]
    assert next(m for m in tasks[0].grounding if m.field == "hazard_class").method == "composed"
    [error] = engine.errors.values()  # the two requests run at once: either may have been the vague one
    assert "is a category, not a hazard class" in error
    assert len(srv.requests) == 4  # the vague one went back to the model twice, then failed alone


def test_none_reads_as_empty_and_a_look_alike_object_is_not_taken(scripted_server, tmp_path):
    empty = {**BASE, "name": "Pills with no box", "container": "none", "co_objects": ["none", "book"],
             "description": "A pill bottle was left on the low coffee table."}
    sofa = {**BASE, "name": "Sofa thing", "hazard_object": "chandelier", "hazard_class": "reduce_tripping_hazards",
            "category": "household_hazard", "placement": "walkway"}
    srv = scripted_server(lambda body: text(reply_json(empty if "idea 1 of 2" in body["messages"][1]["content"] else sofa)))
    engine = _engine(srv, tmp_path, repair_retries=0)
    [task] = engine.run(2)
    assert task.scenario.container is None  # empty: the builder takes the class's own place for medicine
    assert task.scenario.co_objects == ["book"]
    assert any(m.written == "none" and m.method == "dropped" for m in task.grounding)
    [error] = engine.errors.values()
    assert "'chandelier' matches no catalogue name well enough" in error


def test_a_lexicon_word_is_built_as_its_kind_under_the_models_word(scripted_server, tmp_path):
    """The model may name a thing the catalogue lacks by its own word: a word of the household lexicon is
    grounded to its kind's proxy shape and keeps the word (``Scenario.called``), as the offline reader does;
    the grounding says so (method "lexicon", its kind)."""
    from anomalygen.knowledge.lexicon import load_lexicon

    reply = {**BASE, "name": "Cleaner out", "hazard_object": "oven cleaner", "hazard_class": "secure_chemicals",
             "container": "StorageFurniture", "description": "The oven cleaner was left on the low coffee table."}
    srv = scripted_server(lambda body: text(reply_json(reply)))
    engine = _engine(srv, tmp_path, repair_retries=0)
    [task] = engine.from_texts(["The oven cleaner was left on the low coffee table."])
    reading = load_lexicon().read("oven cleaner")
    assert task.scenario.hazard_object == reading.proxy
    assert task.scenario.called == {reading.proxy: "oven cleaner"}
    fault = next(m for m in task.grounding if m.field == "scenario.hazard_object")
    assert (fault.method, fault.kind) == ("lexicon", reading.kind)


def test_a_catalogue_object_written_as_target_stays_itself(scripted_server, tmp_path):
    vase = {**BASE, "name": "Vase at the edge", "hazard_class": "move_fragile_from_edge", "category": "household_hazard",
            "target_asset": "Vase", "hazard_object": "vase", "placement": "table_edge", "container": None,
            "description": "A vase stands at the very edge of the dining table."}
    srv = scripted_server([text(reply_json(vase))])
    [task] = _engine(srv, tmp_path).run(1)
    assert task.scenario.hazard_object == "vase" and task.target_asset != "Pen"
    assert next(m for m in task.grounding if m.field == "target_asset" and m.grounded).method == "class_default"


def test_the_users_line_stays_the_description_through_a_repair(scripted_server, tmp_path):
    line = "Grandma's pill bottle was left on the low coffee table."
    wrong = {**BASE, "name": "Pills", "hazard_object": "flux capacitor", "description": "The model's own rewording."}
    right = {**BASE, "name": "Pills", "description": "Another rewording."}
    srv = scripted_server([text(reply_json(wrong)), text(reply_json(right))])
    engine = _engine(srv, tmp_path, repair_retries=1)
    [task] = engine.from_texts([line])
    assert task.description == line and task.source == "user_text"


def test_a_new_class_in_the_predicate_language_is_checked_and_kept_with_the_run(scripted_server, tmp_path):
    from anomalygen.brainstorm.new_class import save_run_classes
    from anomalygen.runfolder import RunFolder

    new = {"name": "Umbrella open indoors", "why": "An open umbrella blocks the way and its tips poke eyes.",
           "preconditions": [{"name": "category_is", "args": {"object": "$hazard", "category": "backpack"}},
                             {"name": "in_walkway", "args": {"object": "$hazard"}}],
           "recipe": [{"action": "pick", "args": {"object": "$hazard"}},
                      {"action": "place_inside", "args": {"object": "$hazard", "container": "$container"}}],
           "success": [{"name": "inside", "args": {"object": "$hazard", "container": "$container"}}]}
    bad = {**new, "name": "Bad one", "preconditions": [{"name": "is_haunted", "args": {"object": "$hazard"}}]}
    prop = {**BASE, "name": "Odd thing", "hazard_class": "other", "hazard_other": None, "category": "household_hazard",
            "target_asset": "Box", "hazard_object": "backpack", "placement": "walkway", "container": "storage_box",
            "description": "Something odd in the hall.", "new_class": new}
    srv = scripted_server([text(reply_json({**prop, "new_class": bad})), text(reply_json(prop))])
    engine = _engine(srv, tmp_path, repair_retries=1)
    [task] = engine.run(1)
    assert "unknown predicate is_haunted" in srv.requests[1]["messages"][-1]["content"]
    assert task.hazard_class.startswith("llm_umbrella_open_indoors_") and engine.new_classes[0].id == task.hazard_class
    kb = load_kb()
    save_run_classes(tmp_path / "run", engine.new_classes)
    del kb.hazard_classes[task.hazard_class]  # as in a fresh process: opening the run brings it back
    RunFolder(tmp_path / "run")
    assert kb.hazard_classes[task.hazard_class].recipe[1].action == "place_inside"
    del kb.hazard_classes[task.hazard_class]
