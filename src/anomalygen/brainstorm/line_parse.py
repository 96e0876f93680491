"""Reading one plain hazard line: which objects it names, how they relate, which words it uses.

No model is needed: the catalogue's names and aliases are matched word by word (longest phrase
first), the preposition before a name says how it relates to the object at fault ("on the stove",
"next to the curtains", "in the sink"), and noun phrases the catalogue does not know are kept so that
a line about a toaster-oven or paint thinner can be refused by name instead of being read as
something else. Which hazard the words make is decided in ``line_compose.py`` from the mechanisms.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from anomalygen.knowledge.grounding import NameGrounder, name_words, singular
from anomalygen.knowledge.lexicon import Lexicon
from anomalygen.schema import part_labels

_WORD = re.compile(r"[a-z0-9]+_|[a-z0-9]+(?:'[a-z]+)?|[,.;:!?]")

#: Preposition phrases (longest first) and the relation they put the next named object in.
RELATIONS: tuple[tuple[str, str], ...] = (
    ("on top of", "on"), ("right on", "on"), ("draped over", "on"), ("resting on", "on"), ("lying on", "on"),
    ("sitting on", "on"), ("on", "on"), ("onto", "on"), ("atop", "on"), ("over", "on"), ("across", "on"),
    ("in the same cupboard as", "near"), ("in the same cabinet as", "near"), ("on the same shelf as", "near"),
    ("in the same drawer as", "near"), ("same shelf as", "near"), ("same cupboard as", "near"),
    ("at the bottom of", "inside"), ("at the top of", "at"),
    ("inside", "inside"), ("into", "inside"), ("in", "inside"), ("within", "inside"),
    ("next to", "near"), ("close to", "near"), ("near to", "near"), ("right by", "near"), ("up against", "near"),
    ("beside", "near"), ("besides", "near"), ("by", "near"), ("near", "near"), ("against", "near"), ("alongside", "near"),
    ("touching", "near"), ("around", "near"), ("from", "near"), ("under", "under"), ("underneath", "under"),
    ("beneath", "under"), ("below", "under"), ("behind", "near"),
)
#: ^ "at the bottom of" a bucket is in it; at the top of the stairs is on them ("at" is met by an "on"
#: place through ``line_compose.RELATION_FAMILY``). The bottom of the stairs is the floor: not on them.
#: Words that may stand between a preposition and the name it governs ("on the old kitchen stove").
FILLER = frozenset({
    "the", "a", "an", "my", "our", "your", "his", "her", "their", "its", "this", "that", "these", "those", "some",
    "one", "two", "open", "old", "hot", "lit", "full", "running", "kitchen", "bathroom", "bedroom", "living", "room",
    "baby's", "child's", "front", "back", "top", "edge", "of", "low", "high", "big", "small", "little", "wet", "empty",
    "gas", "electric", "main", "nearby", "very", "same", "wooden", "glass",
})
DETERMINERS = frozenset({"a", "an", "the", "some", "my", "our", "your", "his", "her", "their", "this", "that",
                         "these", "those", "several", "few", "two", "three", "loose", "any", "someone's", "grandma's"})
#: Words that end a noun phrase (verbs, auxiliaries, prepositions, conjunctions).
STOP = frozenset({
    "is", "are", "was", "were", "be", "been", "being", "has", "have", "had", "left", "lying", "lies", "lie", "sitting",
    "sits", "sit", "stands", "standing", "stand", "hanging", "hangs", "rests", "resting", "placed", "put", "kept",
    "stored", "and", "or", "but", "with", "while", "where", "which", "that", "so", "because", "since", "of", "to",
    "for", "at", "as", "can", "could", "might", "may", "will", "would", "should", "still", "not", "no", "too",
    "there", "here", "it", "they", "them", "keeps", "gets", "got", "runs", "run", "near", "next", "on", "in", "into",
    "by", "from", "under", "over", "beside", "against", "inside", "onto", "within", "up", "down", "out", "away",
    "all", "just", "right", "again", "unattended", "without", "after", "before", "when", "if", "lit", "plugged",
})
#: Words that open a line or a clause without naming anything: interjections, wh-words, sentence adverbs.
NOT_NOUNS = frozenset({
    "ugh", "oh", "oops", "hey", "wow", "argh", "yikes", "whoops", "um", "er", "hmm", "ah", "uh", "look", "honestly",
    "seriously", "why", "how", "what", "who", "whose", "whom", "when", "where", "please", "again", "also", "yet",
    "overnight", "along", "today", "tonight", "yesterday", "now", "then", "meanwhile", "apparently", "somehow",
})
#: Particles that, after a verb, say a state rather than a place ("left the heater on", "a plugged-in iron").
PARTICLES = frozenset({"on", "in", "off", "open", "running", "up", "out", "down"})
_PRONOUNS = frozenset({"it", "them", "all", "just", "right", "still"})
#: Heads of noun phrases that are not objects at fault (places, people, time, generic words).
NOT_OBJECTS = frozenset({
    "floor", "ground", "edge", "side", "corner", "middle", "top", "bottom", "front", "back", "reach", "height",
    "room", "kitchen", "bathroom", "bedroom", "hallway", "hall", "nursery", "office", "house", "home", "flat",
    "toddler", "child", "children", "kid", "kids", "baby", "babies", "infant", "grandma", "grandpa", "guest", "guests",
    "someone", "somebody", "anyone", "everyone", "people", "person", "family", "parent", "parents", "adult", "adults",
    "dog", "cat", "pet", "pets", "minute", "minutes", "hour", "hours", "day", "days", "night", "week", "weeks",
    "morning", "evening", "time", "while", "way", "path", "walkway", "doorway", "corridor", "thing", "things", "stuff",
    "lot", "pair", "bunch", "pile", "set", "piece", "couple", "bit", "handful", "few", "hand", "hands", "fingers",
    "lunch", "dinner", "breakfast", "use", "water", "heat", "fire", "flame", "flames", "fumes", "smoke", "air", "risk",
    "hazard", "danger", "level", "area", "spot", "place", "position", "wall", "window sill", "sill", "handle",
    part_labels.LID, part_labels.DOOR, part_labels.DRAWER, part_labels.KNOB, part_labels.SWITCH, part_labels.TAP, "plug", "outlet", "socket", "cord", "cable", "shelf", "one", "ones",
    "inch", "inches", "foot", "feet", "metre", "metres", "meter", "meters", "cm", "little",
    *("mum", "mom", "mummy", "mommy", "mother", "dad", "daddy", "father", "granny", "gran", "nan", "nana", "nanna",
      "grandad", "granddad", "grandpa", "gramps", "grandmother", "grandfather", "grandparent", "grandparents",
      "grandkids", "grandchild", "grandchildren", "son", "daughter", "brother", "sister", "husband", "wife",
      "partner", "aunt", "auntie", "uncle", "cousin", "nephew", "niece", "carer", "caregiver", "nanny", "babysitter",
      "resident", "tenant", "landlord", "flatmate", "roommate", "housemate", "neighbour", "neighbor", "visitor",
      "visitors", "toddlers", "teenager", "teen", "boy", "girl", "boys", "girls", "man", "woman", "men", "women",
      "patient", "elderly", "year", "years", "month", "months", "smell", "sound", "noise", "half", "quarter"),
})
#: ^ people, kin and carers (a possessor, "Mum's mug", or the person at risk) and amounts, never a thing at fault
#: Catalogue names that, right after another name, are a part of it ("fridge door", "toilet lid").
PART_NAMES = frozenset({"Door", "Window"})
#: Heads that name a holder of the thing before them ('knife block', 'shoe rack', 'cup holder'): such a
#: compound is neither the thing nor what the head alone is an alias for (a block is a toy block).
HOLDER_HEADS = frozenset({"block", "blocks", "rack", "racks", "stand", "stands", "holder", "holders", "tray", "trays"})
#: Catalogue containers whose "X of Y" names Y as the thing ("a bottle of bleach", "a box of matches").
CONTAINER_WORDS = frozenset({"Bottle", "Box", "Bucket", "bowl", "cup", "mug", "glass", "basket", "storage_box", "plate"})


@dataclass
class Mention:
    """A catalogue name in the line: its token span, the words, and how it relates to the object at fault."""

    start: int
    end: int
    name: str
    words: str
    relation: str | None = None  # on / inside / near / under, from the preposition before it
    prep: str | None = None
    called: str | None = None  # the user's word, when the name is a proxy shape of its kind (the lexicon)
    kind: str | None = None  # the lexicon kind of ``called``
    method: str | None = None  # how the words matched the name: exact, normalised, alias (None: the lexicon)


@dataclass
class ParsedLine:
    line: str
    tokens: list[str]
    mentions: list[Mention] = field(default_factory=list)
    unknown: list[tuple[int, str]] = field(default_factory=list)  # (token index, phrase) the catalogue does not know
    rooms: list[str] = field(default_factory=list)

    @property
    def text(self) -> str:
        return " " + " ".join(t.rstrip("_") for t in self.tokens if t.rstrip("_").isalnum() or "'" in t) + " "

    def says(self, cue: str) -> bool:
        """Does the line use the phrase (whole words, any case)? A two-word verb and particle ("left on",
        "switched off") is also said with its object between them ("left the heater on", up to four words)."""
        words = _WORD.findall(cue.lower())
        if not words:
            return False
        if f" {' '.join(words)} " in self.text:
            return True
        if len(words) == 2 and words[1] in PARTICLES and words[0] not in ("is", "are", "was", "were", "be"):
            toks = self.text.split()
            for i, t in enumerate(toks):
                if t == words[0] and words[1] in toks[i + 2:i + 6]:
                    j = toks.index(words[1], i + 2)
                    if not any(w in STOP and w not in _PRONOUNS and w not in FILLER and w not in DETERMINERS
                               for w in toks[i + 1:j]):
                        return True
        return False

    def said(self, cues) -> list[str]:
        return [c for c in cues if self.says(c)]

    def subjects(self) -> list[Mention]:
        """Named objects not governed by a preposition, in order: candidates for the object at fault."""
        return [m for m in self.mentions if m.relation is None]


_GLUED_PARTICLE = re.compile(r"\b([a-z]+(?:ed|en|ing))-(on|in|off|up|out)\b")


def tokens_of(line: str) -> list[str]:
    """Lower-case word tokens. A hyphenated participle and particle ("plugged-in", "switched-on") is
    one state word: its particle is marked (``in_``) so it is never read as a preposition; ``text``
    says it as two words again."""
    text = _GLUED_PARTICLE.sub(r"\1 \2_", line.lower().replace("’", "'"))
    return _uncontract(_WORD.findall(text))


#: Words after "X's" that make it "X is" or "X has", not a possessive ("the oven's still on",
#: "someone's left the tap running", "the gate's open"): states, particles, adverbs and participles.
_AFTER_IS = frozenset({
    "on", "off", "open", "still", "just", "not", "left", "been", "running", "lit", "up", "out", "hot", "full",
    "empty", "gone", "got", "sitting", "lying", "standing", "burning", "boiling", "plugged", "switched", "turned",
    "there", "here", "always", "now", "again", "wide", "ajar", "dropped", "put", "placed", "balanced", "propped",
    "hanging", "leaning", "wedged", "perched", "stuck", "spilling", "overflowing", "glowing", "unlocked",
})


def _uncontract(tokens: list[str]) -> list[str]:
    out: list[str] = []
    for i, t in enumerate(tokens):
        nxt = tokens[i + 1] if i + 1 < len(tokens) else ""
        if t.endswith("'s") and len(t) > 2 and nxt in _AFTER_IS:
            out += [t[:-2], "is"]
        elif t in ("there's", "here's", "that's", "it's", "what's", "where's", "why's", "how's"):
            out += [t[:-2], "is"]
        elif t.endswith(("'re", "'ve", "'ll", "'d")):
            out.append(t.rsplit("'", 1)[0])
        else:
            out.append(t)
    return out


def relation_before(tokens: list[str], start: int) -> tuple[str | None, str | None]:
    """The preposition that governs the name starting at ``start`` (through up to four determiners
    and modifiers: 'next to the hot flat iron'), if any."""
    i = start
    while i > 0 and start - i < 4 and tokens[i - 1].isalnum() and (tokens[i - 1] in FILLER or tokens[i - 1] not in STOP) \
            and not _is_preposition_end(tokens, i):
        i -= 1
    for phrase, relation in RELATIONS:
        words = phrase.split()
        if i - len(words) >= 0 and tokens[i - len(words):i] == words:
            return relation, phrase
    return None, None


def _is_preposition_end(tokens: list[str], i: int) -> bool:
    """Does a relation phrase end just before position ``i``?"""
    return any(i - len(ph.split()) >= 0 and tokens[i - len(ph.split()):i] == ph.split() for ph, _ in RELATIONS)


def parse_line(line: str, g: NameGrounder, *, longest: int = 4, lexicon: Lexicon | None = None,
               buildable: set[str] | None = None) -> ParsedLine:
    """Mentions of catalogue objects (spelling and aliases, then the household lexicon's words, each a
    proxy shape of its kind under the user's word), with relations; unknown noun phrases; rooms."""
    tokens = tokens_of(line)
    words = [t.removesuffix("'s") for t in tokens]
    pool = set(g.kb.objects)
    taken = [False] * len(words)
    found: list[Mention] = []
    for n in range(longest, 0, -1):
        for i in range(len(words) - n + 1):
            if any(taken[i:i + n]) or not all(w.isalnum() for w in words[i:i + n]):
                continue
            phrase = " ".join(words[i:i + n])
            hit = g.objects.spelled(phrase, pool)
            if hit is not None:
                # an alias is another word for the shape ("bags" for the backpack): the user's word stays
                called = phrase if hit[1] == "alias" and _own_words(hit[0]) != singular(phrase) else None
                found.append(Mention(i, i + n, hit[0], phrase, method=hit[1], called=called))
            elif lexicon is not None and (reading := lexicon.read(phrase, buildable)) is not None \
                    and reading.proxy in pool:
                found.append(Mention(i, i + n, reading.proxy, phrase, called=phrase, kind=reading.kind))
            else:
                continue
            taken[i:i + n] = [True] * n
    found.sort(key=lambda m: m.start)
    found = [_with_modifier(m, words, taken, g, pool) for m in found]
    found, compounds = _merge(found, words, {i for i, t in enumerate(tokens) if t.endswith("'s")})
    for at, end in compounds:
        taken[at:end] = [False] * (end - at)  # a compound of two names is neither: read as unknown words below
    for m in found:
        m.relation, m.prep = relation_before(words, m.start)
    unknown = _unknown_phrases(words, taken, g)
    unknown = sorted(set(unknown) | {(at, " ".join(words[at:end])) for at, end in compounds})
    if lexicon is not None and unknown:
        found, unknown = _nearest_words(found, unknown, words, pool, buildable)
    parsed = ParsedLine(line, tokens, found, rooms=g.rooms.mentions(line))
    parsed.unknown = unknown
    return parsed


def _own_words(name: str) -> str:
    """A catalogue name as words ('toy_block' -> 'toy block', 'PaperTowels' -> 'paper towel')."""
    return singular(name_words(name).lower())


def _nearest_words(found: list[Mention], unknown: list[tuple[int, str]], words: list[str], pool: set[str],
                   buildable: set[str] | None) -> tuple[list[Mention], list[tuple[int, str]]]:
    """Unknown noun phrases that are a lexicon word in other spelling or words ("tool box" for toolbox)
    become mentions of its kind under the user's words (``knowledge.lexicon.nearest``)."""
    from anomalygen.knowledge.lexicon import nearest

    still: list[tuple[int, str]] = []
    for at, phrase in unknown:
        reading = nearest(phrase, buildable)
        if reading is None or reading.proxy not in pool:
            still.append((at, phrase))
            continue
        m = Mention(at, at + len(phrase.split()), reading.proxy, phrase, called=phrase, kind=reading.kind)
        m.relation, m.prep = relation_before(words, m.start)
        found.append(m)
    return sorted(found, key=lambda m: m.start), still


def gerund_compound(words: list[str], m: Mention, states: frozenset[str]) -> str | None:
    """'curling iron', 'ironing board': a name right after an -ing word that says no state is a
    different thing with a compound name (a burning candle or a running tap is the candle or the tap)."""
    k = m.start - 1
    if m.end - m.start != 1 or k < 0:
        return None
    w = words[k]
    if w.endswith("ing") and len(w) > 5 and w not in states and w not in STOP:
        return f"{w} {words[m.start]}"
    return None


def _with_modifier(m: Mention, words: list[str], taken: list[bool], g: NameGrounder, pool: set[str]) -> Mention:
    """'plastic shopping bag': a modifier one or two words before a one-word name may make a longer
    name ('plastic bag'), which wins over the bare word ('bag')."""
    if m.end - m.start != 1:
        return m
    for back in (1, 2):
        k = m.start - back
        if k < 0 or taken[k] or not words[k].isalnum() or words[k] in STOP:
            continue
        hit = g.objects.spelled(f"{words[k]} {words[m.start]}", pool)
        if hit is not None:
            return Mention(k, m.end, hit[0], " ".join(words[k:m.end]))
    return m


def _merge(found: list[Mention], words: list[str],
           possessive: frozenset[int] | set[int] = frozenset()) -> tuple[list[Mention], list[tuple[int, int]]]:
    """'bottle of bleach' -> the bleach; 'fridge door' -> the fridge; a name said twice -> once.

    Also returns the spans of compounds that name neither of their parts: a holder word matched as a
    one-word alias after another name ('knife block': a block only by alias) is another thing."""
    out: list[Mention] = []
    compounds: list[tuple[int, int]] = []
    for m in found:
        prev = out[-1] if out else None
        if prev is not None and m.name in PART_NAMES and m.start == prev.end:
            continue  # the fridge('s) door
        if prev is not None and m.start == prev.end:
            if m.name in CONTAINER_WORDS and prev.name not in CONTAINER_WORDS:
                continue  # 'a vitamin bottle', 'the bleach jug': the container of a thing is the thing
            if m.method == "alias" and m.end - m.start == 1 and prev.kind is None and m.kind is None \
                    and words[m.start] in HOLDER_HEADS and prev.end - 1 not in possessive:
                out.pop()  # 'knife block', 'shoe rack': the head is the alias's object only in name
                compounds.append((prev.start, m.end))
                continue
            out[-1] = m  # 'bread knife', 'glass vase': the last noun names the thing
            continue
        if prev is not None and prev.name in CONTAINER_WORDS and words[prev.end:prev.end + 1] == ["of"] \
                and m.start - prev.end <= 3:
            out[-1] = m  # a bottle of bleach is the bleach
            continue
        if prev is not None and m.name in PART_NAMES and words[m.end:m.end + 1] == ["of"]:
            pass
        out.append(m)
    # "the door of the oven": the part goes, the owner stays
    return [m for i, m in enumerate(out) if not (m.name in PART_NAMES and i + 1 < len(out)
                                                  and words[m.end:m.end + 1] == ["of"] and out[i + 1].start - m.end <= 3)], compounds


def word_classes(word: str) -> set[str]:
    """The parts of speech a word can have (NOUN, VERB, ADJ, ADV, ...), from LemmInflect's lemma
    tables (MIT; derived from the SPECIALIST Lexicon); empty for a word they do not hold."""
    from lemminflect import getAllLemmas

    return set(getAllLemmas(word))


def _can_be_noun(word: str) -> bool:
    """A word the tables hold only as another part of speech is no noun ('balanced', 'along'); a word
    they do not hold ('worktop', 'paracetamol') may be one."""
    classes = word_classes(word)
    return not classes or "NOUN" in classes


def _unknown_phrases(words: list[str], taken: list[bool], g: NameGrounder) -> list[tuple[int, str]]:
    """Noun phrases (after a determiner, or opening the line) that name no catalogue object."""
    out: list[tuple[int, str]] = []
    starts = [0] + [i + 1 for i, w in enumerate(words) if w in DETERMINERS or w == "of"]
    for s in starts:
        chunk: list[int] = []
        i = s
        while i < len(words) and len(chunk) < 3 and words[i].isalnum() and words[i] not in STOP \
                and words[i] not in DETERMINERS and words[i] not in NOT_NOUNS:
            if chunk and words[chunk[-1]] in NOT_OBJECTS and word_classes(words[i]) & {"VERB"}:
                break  # 'the toddler plays', 'where the kids play': a person and a verb, not a name
            chunk.append(i)
            i += 1
        if chunk and not _can_be_noun(words[chunk[-1]]):
            continue  # 'someone balanced', 'uncooked': no noun ends the phrase
        if not chunk or any(taken[k] for k in chunk):
            continue
        head = singular(words[chunk[-1]])
        if head in NOT_OBJECTS or words[chunk[-1]] in NOT_OBJECTS or g.is_room(words[chunk[-1]]) or len(head) < 3:
            continue
        phrase = " ".join(words[k] for k in chunk)
        if g.placements.spelled(phrase, set(g.placements.names)) is not None:
            continue
        if i < len(words) and words[i] == "of" and any(taken[i + 1:i + 4]):
            continue  # 'a loaf of', 'a tray of': a quantity of the named thing that follows
        out.append((chunk[0], phrase))
    return sorted(set(out))
