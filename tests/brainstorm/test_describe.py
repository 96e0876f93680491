"""Every fragment of a generated description agrees with its task (issue 39).

A blind reader of the old phrase-bank texts found persona remarks unrelated to the hazard, spill words
for pills and kitchen words in bathrooms. Each fragment now carries a tag of what it was drawn for;
these tests draw ideas from every role and check every tag against the idea it describes."""

from __future__ import annotations

import numpy as np
import pytest

from anomalygen.brainstorm.describe import Fragment, _a, person_fits, words
from anomalygen.brainstorm.idea_sampler import IdeaSampler, idea_scene
from anomalygen.brainstorm.realise import fragments, nice, realise
from anomalygen.knowledge import load_kb
from anomalygen.knowledge.households import load_households


@pytest.fixture(scope="module")
def drawn():
    """(idea, fragments, description) for 40 fresh ideas of every role, each from its own seed."""
    kb = load_kb()
    out = []
    for i, role in enumerate(sorted(kb.roles)):
        sampler = IdeaSampler(kb, kb.roles[role])
        for k in range(40):
            idea = sampler.fresh(np.random.default_rng([i, k]), agent=role, agent_index=i, round_=1)
            frags = fragments(idea, kb, np.random.default_rng([i, k, 1]))  # realise draws them first
            out.append((idea, frags, realise(idea, kb, np.random.default_rng([i, k, 1])).description))
    return kb, out


def _tag_problems(kb, idea, frags: list[Fragment]) -> list[str]:
    hc = kb.hazard_classes[idea.class_id]
    p = idea.placement
    composed = hc.composition.place if hc.composition is not None and not hc.composition.legacy else None
    bad = []
    for f in frags:
        if f.kind == "place" and (f.fits != p.key or p.other is not None or composed in words()["place_by_fragment"]):
            bad.append(f"place phrase {f.text!r} is for {f.fits}, the task is {p.key}")
        elif f.kind == "relation" and (f.fits != p.relation or nice(p.other) not in f.text):
            bad.append(f"relation phrase {f.text!r} does not say {p.relation} {p.other}")
        elif f.kind == "place_fragment" and f.fits != composed:
            bad.append(f"place {f.text!r} is for {f.fits}, the class's place is {composed}")
        elif f.kind == "state" and not ((hc.articulation is not None and f.fits == hc.articulation.initial_state)
                                        or (hc.composition is not None and f.fits == hc.composition.condition)):
            bad.append(f"state {f.text!r} is for {f.fits}")
        elif f.kind == "room" and f.fits != idea.room:
            bad.append(f"room {f.fits} is not {idea.room}")
        elif f.kind in ("danger", "fix") and f.fits != idea.class_id:
            bad.append(f"{f.kind} {f.text!r} belongs to {f.fits}, not {idea.class_id}")
        elif f.kind == "danger" and f.text not in (hc.why, *hc.why_by.values()):
            bad.append(f"danger {f.text!r} is not the class's own")
        elif f.kind == "person" and not (f.fits in hc.people or f.fits in hc.at_risk):
            bad.append(f"person {f.fits!r} is not one the class puts at risk")
    return bad


def test_every_fragment_agrees_with_its_task(drawn):
    kb, out = drawn
    problems = [f"{idea.class_id}: {b}" for idea, frags, _ in out for b in _tag_problems(kb, idea, frags)]
    assert problems == []
    kinds = {f.kind for _, frags, _ in out for f in frags}
    assert {"place", "relation", "state", "danger", "fix", "person", "room", "sentence"} <= kinds


def test_the_text_is_its_fragments_and_nothing_from_another_mechanism(drawn):
    kb, out = drawn
    whys = {hc.id: hc.why for hc in kb.hazard_classes.values()}
    remarks = [r.perspective for r in kb.roles.values() if r.perspective]
    for idea, frags, description in out:
        for f in frags:
            if f.kind in ("place", "relation", "place_fragment", "state", "danger"):
                head = f.text.split(",")[0]  # the room may stand before a trailing remark
                assert head in description, (f.text, description)
        foreign = [c for c, why in whys.items() if why in description and why != whys[idea.class_id]]
        assert foreign == [], (idea.class_id, foreign, description)
        assert not any(r in description for r in remarks), description  # a role's remark is not in the text
        assert kb.roles[idea.agent].name not in description


def test_the_person_at_risk_fits_the_scene(drawn):
    _, out = drawn
    for idea, _, _ in out:
        assert person_fits(idea.person, **idea_scene(idea)), (idea.person, idea.room, idea.placement)
    assert not person_fits("the cook", room="bedroom", names=["iron", "table"])
    assert person_fits("a child in the bath", room="bathroom", names=["hair_dryer", "Bathtub"])
    assert not person_fits("a child in the bath", room="bathroom", names=["hair_dryer", "Sink"])


def test_fixture_place_phrases_say_nothing_the_scene_may_lack():
    """A place phrase for a support kind names no fixture other than that support (no sink or hob on
    'the counter'), so it is true in every room the counter stands in."""
    fixtures = [nice(n).lower() for n in load_households().fixtures]
    for key, phrases in words()["place"].items():
        for phrase in phrases:
            named = [f for f in fixtures if f in phrase and f not in key.replace("_", " ")]
            assert named == [], (key, phrase, named)


@pytest.mark.parametrize(("phrase", "said"), [
    ("USB stick", "a USB stick"), ("HDMI cable", "an HDMI cable"), ("mouldy bread", "some mouldy bread"),
    ("box of leftovers", "a box of leftovers"), ("pliers", "some pliers"), ("iron", "an iron"),
    ("glass", "a glass"),
])
def test_articles_follow_the_head_noun(phrase, said):
    assert _a(phrase) == said


def test_the_situation_says_what_the_danger_sentence_relies_on(drawn):
    """A pot's handle that sticks out and the curtains a heater left on stands by are said in the
    situation, not only assumed by the danger sentence (a blind reading of seed 8 found both missing)."""
    kb, out = drawn
    checked = 0
    for idea, frags, _text in out:
        hc = kb.hazard_classes[idea.class_id]
        situation = next(f.text for f in frags if f.kind == "sentence")
        if hc.composition is not None and hc.composition.condition == "handle_out":
            assert "handle sticking out" in situation, situation
            checked += 1
        if hc.articulation is not None and hc.about_target and idea.placement.other and idea.placement.relation == "near":
            assert nice(idea.placement.other) in situation, situation
            checked += 1
    assert checked > 0


def test_a_class_reason_is_the_one_for_its_object():
    """One reason per class did not fit every object (a blind reading of seed 9: food-scraps wording
    for a paper ball, a mouthing baby for scissors by a crib, burns for a washing machine): a class's
    ``why_by`` gives the reason for a category or property, and the description uses it."""
    kb = load_kb()

    def why(cls, obj):
        return kb.hazard_classes[cls].why_for(obj, kb.objects[obj].properties)

    assert "smother" not in why("pick_up_floor_litter", "paper_ball") and "smother" in why("pick_up_floor_litter", "plastic_bag")
    assert "mouth" not in why("sharp_near_crib", "Scissors") and "mouth" in why("choking_near_crib", "marble")
    assert "burn" not in why("switch_off_appliance", "WashingMachine") and "burn" in why("switch_off_appliance", "Toaster")
    assert "foot" not in why("store_sharp_objects", "needle").split("ends up")[0]
    for cls in kb.hazard_classes.values():
        for key in cls.why_by:
            assert key in kb.objects or any(key in o.properties for o in kb.objects.values()), (cls.id, key)
