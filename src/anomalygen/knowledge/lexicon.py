"""The household lexicon: the words people use for things, mapped to kinds with properties and proxy shapes.

Why: the catalogue holds 126 shapes, but people write "oven cleaner", "paracetamol", "a tea towel",
"raw chicken". Each such word names a *kind* (household chemical, medicine, flammable fabric,
perishable food) whose hazard properties the mechanisms condition on. A word the catalogue lacks is
built from a proxy shape of the same kind and keeps the user's own name (``Scenario.called``): an
oven cleaner is a chemical bottle called oven cleaner, never a "cleaning spray". A word whose kind has
no shape of its own is not in the lexicon, and the reader refuses it by name.

The data is ``data/knowledge/lexicon.json`` (written for this project; see its ``_about``). A test
checks that every proxy of a kind carries all of the kind's properties, so a proxy can never add a
danger by losing one, and that no word names two kinds.
"""

from __future__ import annotations

import functools
import json
from importlib.resources import files

from pydantic import BaseModel, ConfigDict, Field, model_validator

from anomalygen.knowledge.grounding import normalise


class Kind(BaseModel):
    """One kind of household thing: what the mechanisms read of it and the shapes that can stand for it."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    id: str
    words: str = Field(description="the kind in a sentence: 'household chemical'")
    properties: tuple[str, ...] = Field(description="hazard properties every thing of this kind has")
    proxies: tuple[str, ...] = Field(min_length=1, description="catalogue shapes that can stand for it, best first")
    rooms: tuple[str, ...] = ()
    places: tuple[str, ...] = ()
    size_m: tuple[float, float] | None = None
    mass_kg: tuple[float, float] | None = None


class Word(BaseModel):
    """One word (or multi-word name) of the lexicon and its spellings."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    word: str
    kind: str
    variants: tuple[str, ...] = ()
    proxy: str | None = Field(None, description="the kind's proxy that fits this word best; None: the kind's first")


class Reading(BaseModel):
    """What the lexicon says of a phrase: its word, kind and the shape it is built from."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    word: str
    kind: str
    proxy: str


class Lexicon(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    kinds: dict[str, Kind]
    words: dict[str, Word]

    @model_validator(mode="after")
    def _consistent(self) -> Lexicon:
        for w in self.words.values():
            kind = self.kinds.get(w.kind)
            if kind is None:
                raise ValueError(f"lexicon word {w.word!r} has the unknown kind {w.kind!r}")
            if w.proxy is not None and w.proxy not in kind.proxies:
                raise ValueError(f"lexicon word {w.word!r}: proxy {w.proxy!r} is not a proxy of kind {w.kind!r}")
        return self

    @functools.cached_property
    def _keys(self) -> dict[str, str]:
        out: dict[str, str] = {}
        for w in self.words.values():
            for spelling in (w.word, *w.variants):
                out.setdefault(normalise(spelling), w.word)
        return out

    def keys(self) -> dict[str, str]:
        """Every normalised spelling -> its word."""
        return dict(self._keys)

    def read(self, phrase: str, buildable: set[str] | None = None) -> Reading | None:
        """The reading of a phrase ("oven cleaners", "Oven-cleaner"), or None when the lexicon does not
        hold it. With ``buildable``, the proxy is the word's (else its kind's) first one that can be built."""
        word = self._keys.get(normalise(phrase))
        if word is None:
            return None
        w = self.words[word]
        kind = self.kinds[w.kind]
        order = [w.proxy] if w.proxy else []
        order += [p for p in kind.proxies if p not in order]
        if buildable is not None:
            order = [p for p in order if p in buildable]
        if not order:
            return None
        return Reading(word=w.word, kind=w.kind, proxy=order[0])


#: A phrase the lexicon does not spell is read as the word nearest in meaning only when it is that
#: close (cosine, all-MiniLM-L6-v2) and that far ahead of the nearest word of any other kind. Measured:
#: "tool box" -> toolbox 0.92 (next kind 0.62) is kept; "garden clippers" -> hair clipper 0.64,
#: "cigarette" -> cigarette lighter 0.73, "fridge magnet" -> magnet 0.72 are not (the last is read
#: by its head noun instead: the reader's compounds are head-final).
NEAREST_FLOOR = 0.85
NEAREST_MARGIN = 0.1


@functools.cache
def _word_vectors():
    from anomalygen.embedding import embed

    lex = load_lexicon()
    names = list(lex.words)
    return names, embed(names)


def nearest(phrase: str, buildable: set[str] | None = None) -> Reading | None:
    """The reading of the lexicon word nearest in meaning to ``phrase``, or None when no word is near
    enough (``NEAREST_FLOOR``) or a word of another kind is nearly as near (``NEAREST_MARGIN``)."""
    import numpy as np

    from anomalygen.embedding import embed

    lex = load_lexicon()
    names, vecs = _word_vectors()
    sims = vecs @ embed([phrase])[0]
    order = np.argsort(-sims, kind="stable")
    best = names[int(order[0])]
    kind = lex.words[best].kind
    other = next((float(sims[int(i)]) for i in order[1:] if lex.words[names[int(i)]].kind != kind), 0.0)
    if float(sims[int(order[0])]) < NEAREST_FLOOR or float(sims[int(order[0])]) - other < NEAREST_MARGIN:
        return None
    return lex.read(best, buildable)


@functools.cache
def load_lexicon() -> Lexicon:
    raw = json.loads(files("anomalygen.data.knowledge").joinpath("lexicon.json").read_text(encoding="utf-8"))
    kinds = {k: Kind(id=k, **v) for k, v in raw["kinds"].items()}
    words = {k: Word(word=k, **v) for k, v in raw["words"].items()}
    return Lexicon(kinds=kinds, words=words)
