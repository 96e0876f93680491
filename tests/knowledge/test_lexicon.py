"""The household lexicon (``data/knowledge/lexicon.json``): words -> kinds -> proxy shapes of the same kind.

A proxy may only stand for a word when it is the same kind of thing: it carries every property of the
word's kind (the mechanisms read properties), it exists in the knowledge base and the catalogue can
build it. These tests hold the data to that, whatever words are added later.
"""

from __future__ import annotations

import pytest

from anomalygen.knowledge import load_kb
from anomalygen.knowledge.grounding import normalise
from anomalygen.knowledge.lexicon import load_lexicon


@pytest.fixture(scope="module")
def lex():
    return load_lexicon()


def test_covers_at_least_400_household_words(lex):
    assert len(lex.words) >= 400
    assert len(lex.keys()) > len(lex.words)  # plurals and other spellings read too


NEUTRAL = {"container", "lockable"}  # say how a thing is stored, not what harm it does


def test_every_proxy_is_a_known_shape_with_exactly_the_properties_of_its_kind(lex):
    """The mechanisms read properties: a proxy lacking one would lose the word's danger, a proxy with an
    extra one would add a danger the word does not have (a radio built from a camera would be fragile)."""
    kb = load_kb()
    for kind in lex.kinds.values():
        for proxy in kind.proxies:
            assert proxy in kb.objects, (kind.id, proxy)
            theirs = set(kb.objects[proxy].properties) - NEUTRAL
            assert theirs == set(kind.properties) - NEUTRAL, f"{proxy} stands for {kind.id}: {sorted(theirs)} vs {kind.properties}"


def test_no_word_is_built_from_a_shape_a_mechanism_names():
    """Stairs and cribs are named by mechanisms (things on the stairs, cords by the crib): a ladder or a
    bed built from their shapes would carry their dangers. Only words for the same thing may use them."""
    lex = load_lexicon()
    for w in lex.words.values():
        reading = lex.read(w.word)
        if reading.proxy in ("Stairs", "Crib"):
            assert any(x in w.word for x in ("stair", "step", "crib", "cot", "bassinet", "cradle")), w.word


def test_every_kind_has_a_buildable_proxy(lex):
    from anomalygen.brainstorm.drawable import catalogue

    built = set(catalogue())
    for kind in lex.kinds.values():
        assert any(p in built for p in kind.proxies), kind.id


def test_no_spelling_names_two_words(lex):
    seen: dict[str, str] = {}
    for w in lex.words.values():
        for spelling in (w.word, *w.variants):
            key = normalise(spelling)
            assert seen.setdefault(key, w.word) == w.word, f"{spelling!r} is both {seen[key]!r} and {w.word!r}"


def test_every_spelling_of_a_word_reads_the_same(lex):
    for w in lex.words.values():
        readings = {lex.read(s) for s in (w.word, *w.variants, w.word.upper(), w.word.replace(" ", "-"))}
        assert len(readings) == 1 and None not in readings, (w.word, readings)


def test_the_catalogue_name_of_a_kind_is_not_shadowed():
    """A word the catalogue already names is read by the catalogue, not as a proxy: the lexicon only
    adds words."""
    from anomalygen.brainstorm.line_parse import parse_line
    from anomalygen.knowledge.grounding import NameGrounder

    g = NameGrounder(load_kb())
    p = parse_line("The kettle is next to the sink.", g, lexicon=load_lexicon())
    assert [(m.name, m.called) for m in p.mentions] == [("Kettle", None), ("Sink", None)]
