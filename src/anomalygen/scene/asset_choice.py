"""The choice of one asset: which catalogue entry a name means, which generated variant, how big, in
which state. (Which objects a scene holds and the role each plays is ``casting.py``.)

The paper has an LLM name objects, retrieves assets by Sentence-BERT and asks a VLM whether they fit.
Offline we do the same with the knowledge base: target candidates are generated variants of the
target category ranked by SBERT similarity of their descriptions to the proposal text; other objects
are catalogue names (or, for unknown names, the nearest catalogue entry by SBERT retrieval); each
candidate passes a knowledge-based plausibility check (size within the category's range, the
articulated part the task needs exists, a contained object fits the container's opening). When every
candidate is rejected the item fails with the reason, never a silent substitute.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from anomalygen.errors import ItemFailed
from anomalygen.schema import SWITCH_LABELS, ArticulationUse, ObjectRole, TaskProposal, part_labels

TARGET_CANDIDATES = 3  # generated variants ranked per target
ROOM_MARGIN = 1.4  # aim a redrawn container this much roomier than the thing it must hold: a tight fit
# builds but the robot cannot drop or slide the thing in (a milk carton over a bin just its size)
EXTRA_DRAWS_FOR_PARTS = 8  # further variants drawn when none so far has the part the task needs
FIXED_SIZE = 0.55  # m: assets at least this big are furniture (welded), smaller ones are loose
MIN_OPEN_HINGE = math.radians(50)  # "fridge door open >= 45 deg", with a margin


@dataclass
class Chosen:
    """One object instance the scene will contain (before placement)."""

    name: str  # instance name, e.g. kitchen_knife_0
    catalogue: str  # catalogue / vocabulary name
    role: ObjectRole
    asset: object  # anomalygen.assets.model.Asset
    joint_values: dict[str, float] = field(default_factory=dict)  # unprefixed joint -> value
    states: list[str] = field(default_factory=list)  # instance states the builder sets (world/states.py)

    @property
    def size(self) -> float:
        return float(self.asset.size)

    @property
    def fixed(self) -> bool:
        return (self.size >= FIXED_SIZE or self.catalogue in _ALWAYS_FIXED) and self.catalogue not in _NEVER_FIXED


# long but light things a person picks up: a 2 m cable across a walkway is the hazard, and welded in
# place the robot could never lift it (suction found no free body to hold)
_NEVER_FIXED = {"power_cable", "extension_cord", "phone_charger"}
_ALWAYS_FIXED = {
    "Refrigerator",
    "StorageFurniture",
    "Dishwasher",
    "WashingMachine",
    "Oven",
    "Door",
    "Window",
    "Table",
    "Toilet",
    "counter",
    "shelf",
    "medicine_cabinet",
    # a home safe is bolted to the floor (its makers ship the anchors): loose, an 18 kg safe of 37 cm
    # tipped onto its back when the arm brushed its door, open against its stop
    "Safe",
}


@lru_cache(maxsize=1)
def catalogue_names() -> tuple[str, ...]:
    """Every catalogue name the builder can instantiate."""
    from anomalygen.assets.core import available_names

    return tuple(available_names())


def resolve_name(name: str) -> str:
    """A catalogue name for ``name``: itself, a case-insensitive match, or the SBERT nearest entry."""
    names = catalogue_names()
    if name in names:
        return name
    lowered = {n.lower(): n for n in names}
    key = name.lower().replace(" ", "_")
    if key in lowered:
        return lowered[key]
    try:
        from anomalygen.assets import retrieve

        hits = retrieve(name.replace("_", " "), k=1)
    except ImportError:
        raise ItemFailed(f"object {name!r} is not in the asset catalogue") from None
    if not hits:
        raise ItemFailed(f"object {name!r} is not in the asset catalogue and retrieval found nothing")
    hit = hits[0]
    found = (
        getattr(hit, "name", None)
        or getattr(hit, "category", None)
        or (hit[0] if isinstance(hit, tuple) else str(hit))
    )
    found = getattr(found, "name", found)
    if found not in names:
        raise ItemFailed(f"object {name!r} retrieved {found!r}, which has no generator")
    return found


def kb_size_range(kb, catalogue: str) -> tuple[float, float] | None:
    info = kb.objects.get(catalogue) if kb is not None else None
    return tuple(info.size_range) if info is not None else None


def size_bounds(kb, catalogue: str) -> tuple[float, float]:
    """The sizes a name is drawn in: the knowledge base's range intersected with the generator's."""
    from anomalygen.assets.names import size_range

    lo, hi = size_range(catalogue)
    kb_range = kb_size_range(kb, catalogue)
    if kb_range is not None:
        lo, hi = max(lo, kb_range[0]), min(hi, kb_range[1])
        if lo > hi:  # ranges disagree: trust the generator's own plausible range
            lo, hi = size_range(catalogue)
    return lo, hi


def biggest_cavity(asset):
    """The cavity things go in and are put away in: the roomiest by volume."""
    return max(asset.cavities, key=lambda c: float(np.prod(c.half_extents)))


def cavity_cap(asset) -> float:
    """Largest thing the biggest cavity takes: a fifth less than its smallest extent, or than its
    floor's long side when it is open above (a power strip lies flat in a sink, turned to fit)."""
    cav = biggest_cavity(asset)
    if cav.open_above:
        return 0.8 * 2 * float(max(cav.half_extents[0], cav.half_extents[1]))
    return 0.8 * 2 * float(min(cav.half_extents))


def container_room(asset) -> float:
    """Longest thing that lies flat in the container's biggest cavity (along its long side)."""
    cav = biggest_cavity(asset)
    return 0.95 * 2 * float(max(cav.half_extents[0], cav.half_extents[1]))


def choose_size(
    kb, catalogue: str, rng: np.random.Generator, *, cap: float | None = None, preferred: float | None = None
) -> float:
    """Largest dimension: uniform in the knowledge base's range (intersected with the generator's),
    clamped by ``cap`` (the spatial rule of a container opening or a support surface). A
    ``preferred`` size (an engine's, e.g. the LLM's) is used instead of the draw, clamped the same way."""
    lo, hi = size_bounds(kb, catalogue)
    if cap is not None:
        if cap < lo:
            raise ItemFailed(f"{catalogue} (at least {lo:.2f} m) does not fit a {cap:.2f} m space")
        hi = min(hi, cap)
    if preferred is not None:
        return float(min(hi, max(lo, preferred)))
    return float(rng.uniform(lo, hi))


def proposal_text(task: TaskProposal) -> str:
    return f"{task.name}. {task.description}"


def rank_by_similarity(text: str, descriptions: list[str]) -> np.ndarray:
    """Order of ``descriptions`` by SBERT cosine similarity to ``text`` (best first)."""
    from anomalygen.embedding import embed

    vecs = embed([text, *descriptions])
    sims = vecs[1:] @ vecs[0]
    return np.argsort(-sims, kind="stable")


def needed_parts(task: TaskProposal, catalogue: str, hc, role: ObjectRole | None = None) -> list[ArticulationUse]:
    """Articulations the task (or its hazard class template) requires of this catalogue object.

    A task that names none still needs the part its class is about on the object playing that role
    (a drawer on the table of a close-the-drawer scene): without it every candidate drawn for the
    role counts as plausible, and a table with no drawer fails the build afterwards."""
    out = [a for a in task.articulations if a.object == catalogue]
    art = getattr(hc, "articulation", None)
    if not out and art is not None and role is not None:
        if art.variable == "$target":  # the target, built in the target's or (being at fault) the hazard's role
            plays = role in (ObjectRole.TARGET, ObjectRole.HAZARD) and _same_category(catalogue, task.target_asset)
        else:
            plays = art.variable == hc.hazard_variable and role is ObjectRole.HAZARD
        if plays:
            out.append(ArticulationUse(object=catalogue, part=art.part, function=art.function,
                                       initial_state=art.initial_state, target_state=art.target_state))
    return out


def _same_category(catalogue: str, name: str) -> bool:
    try:
        return resolve_name(name) == catalogue
    except ItemFailed:
        return False


def plausibility_problem(
    asset, catalogue: str, kb, parts: list[ArticulationUse], *, cap: float | None, states: frozenset[str] = frozenset()
) -> str | None:
    """The knowledge-based verification of a candidate: None when plausible, else why not."""
    rng = kb_size_range(kb, catalogue)
    if rng is not None and not (rng[0] * 0.8 <= asset.size <= rng[1] * 1.25):
        return (
            f"{catalogue} candidate is {asset.size:.2f} m, outside the plausible {rng[0]:.2f}-{rng[1]:.2f} m"
        )
    if cap is not None and asset.size > cap * 1.001:
        return f"{catalogue} candidate ({asset.size:.2f} m) does not fit its {cap:.2f} m space"
    for part in parts:
        if part.initial_state in ("open", "closed", "on", "off") and not joints_with_label(asset, part.part):
            return f"{catalogue} candidate has no '{part.part}' joint"
    if states:
        from anomalygen.world.states import why_cannot_show

        for state in sorted(states):
            why = why_cannot_show(asset, state)
            if why is not None:
                return f"{catalogue} candidate {why}"
    return None


def joints_with_label(asset, label: str) -> list:
    """Joints whose (KB-normalised) label is one of ``label``'s alternatives ('door|drawer'); any
    on/off control stands for another (the knowledge base says knob where an asset has a switch)."""
    wanted = {part_labels.canonical(x) for x in part_labels.alternatives(label)}
    if any(part_labels.is_switch(x) for x in wanted):
        wanted |= set(SWITCH_LABELS)
    return [j for j in asset.joints if part_labels.canonical(j.label) in wanted]


def wanted_states(task: TaskProposal, catalogue: str, hc, role: ObjectRole) -> frozenset[str]:
    """The states the task asks this object to show (its scenario's states for the category; for the
    object at fault, also its class's ``has_state`` preconditions): a candidate that cannot show one
    (a pot with two side grips cannot have its handle out) gives way to another draw."""
    asked = set(task.scenario.states.get(catalogue, []))
    if role is ObjectRole.HAZARD and hc is not None:
        asked |= {str(c.args.get("state")) for c in hc.preconditions
                  if c.name == "has_state" and not c.negate and c.args.get("object") == hc.hazard_variable}
    return frozenset(asked)


def pick_asset(
    catalogue: str,
    *,
    role: ObjectRole,
    kb,
    task: TaskProposal,
    hc,
    rng: np.random.Generator,
    cap: float | None = None,
    rank: bool = False,
    size: float | None = None,
    real: bool = True,
    room_for: float | None = None,
    stores: float | None = None,
):
    """Generate candidates, verify them, rank the target ones by SBERT; the first plausible one wins.

    A category with real (packaged) models draws those (``real``: ``build.real_assets``); a real
    candidate that does not fit here (too big for the space, without the part the task needs, an
    interior too small for the ``room_for`` m thing to go in it) gives way to the procedural one
    drawn with the same seed and size; a procedural one still too small is drawn again, bigger.
    ``stores``: the least size of what the task puts away in it; a container with less room gives way to one with enough (more are drawn), and when none
    has it the roomiest is returned, for the caller to say what does not fit."""
    from anomalygen.assets.core import draw, generate

    parts = needed_parts(task, catalogue, hc, role)
    states = wanted_states(task, catalogue, hc, role)
    n = TARGET_CANDIDATES if rank else 2
    seeds = [int(s) for s in rng.integers(0, 2**31 - 1, size=n)]
    candidates, problems, cramped = [], [], []
    drawn = 0
    roomier: float | None = None  # after a cramped container: the size whose room would hold ``stores``
    # a needed part may be on only some variants (one table in three has a drawer): draw on, up to
    # EXTRA_DRAWS_FOR_PARTS more, until one has it; a scene whose first draws pass is unchanged
    while drawn < n or ((parts or stores or room_for) and not candidates and drawn < n + EXTRA_DRAWS_FOR_PARTS):
        s = seeds[drawn] if drawn < n else int(rng.integers(0, 2**31 - 1))
        drawn += 1
        want = choose_size(kb, catalogue, rng, cap=cap, preferred=size if roomier is None else roomier)
        asset = draw(catalogue, s, size=want, real=real)
        problem = plausibility_problem(asset, catalogue, kb, parts, cap=cap, states=states)
        if problem is None and asset.package is not None and room_for and asset.cavities \
                and cavity_cap(asset) < room_for:
            problem = f"its interior takes {cavity_cap(asset):.2f} m, less than the {room_for:.2f} m to go in"
        if problem is not None and asset.package is not None:
            problems.append(f"real model {asset.asset_id}: {problem}")
            asset = generate(catalogue, s, size=want)
            problem = plausibility_problem(asset, catalogue, kb, parts, cap=cap, states=states)
        # too small for what goes in (a sink for the kettle a line puts in it) or is put away in it: a
        # container's room grows with its size, so the next draws aim where this one would hold it
        # (the generator checked the roomiest size; a uniform draw rarely lands there)
        short = next(((need, have) for need, have in ((room_for, cavity_cap), (stores, container_room))
                      if problem is None and need and asset.cavities and have(asset) < need), None)
        if short is not None:
            need, have = short
            cramped.append(asset)
            roomier = max(roomier or 0.0, asset.size * need / max(have(asset), 1e-6) * ROOM_MARGIN)
            continue
        if problem is None:
            candidates.append(asset)
        else:
            problems.append(problem)
    if not candidates and cramped:
        candidates = [max(cramped, key=container_room)]
    if not candidates:
        raise ItemFailed(f"every {catalogue} candidate was rejected: {problems[0]}")
    if rank and len(candidates) > 1:
        order = rank_by_similarity(proposal_text(task), [c.description for c in candidates])
        candidates = [candidates[i] for i in order]
    return candidates[0]


def far_end(joint) -> float:
    """The end of the joint's range away from its closed value (fully open, fully on)."""
    lo, hi = joint.range
    closed = joint.closed_value
    return hi if abs(hi - closed) >= abs(lo - closed) else lo


def open_value(joint, state: str, rng: np.random.Generator) -> float:
    """A joint value for a part state: closed/off at the safe value, open/on far enough to be real.

    Hinged doors open at least ~50 degrees (the issue's "fridge door open >= 45 deg"), drawers and
    sliding sashes 60-90 % of their travel, knobs and switches to 70-100 % of their range.
    """
    closed = joint.closed_value
    if state in ("closed", "off"):
        return float(closed)
    far = far_end(joint)
    span = abs(far - closed)
    sign = 1.0 if far >= closed else -1.0
    if state == "on" or part_labels.is_switch(joint.label):
        frac = rng.uniform(0.7, 0.95)
        return float(closed + sign * frac * span)
    if joint.type == "hinge":
        lo_amt = min(max(MIN_OPEN_HINGE, 0.5 * span), 0.95 * span)
        amount = rng.uniform(lo_amt, max(lo_amt, 0.9 * span))
        return float(closed + sign * amount)
    return float(closed + sign * rng.uniform(0.6, 0.9) * span)


def set_articulations(chosen: Chosen, uses: list[tuple[str, str]], rng: np.random.Generator) -> None:
    """Apply (part label, initial state) pairs to every matching joint of the chosen asset."""
    for label, state in uses:
        if state == "other":
            continue
        joints = joints_with_label(chosen.asset, label)
        if state in ("open", "on") and len(joints) > 1 and "|" in label:
            # 'door|drawer': opening one kind is enough for the hazard; prefer the first alternative found
            canonical = part_labels.canonical
            first = next(
                canonical(x) for x in part_labels.alternatives(label) if any(canonical(j.label) == canonical(x) for j in joints)
            )
            joints = [j for j in joints if canonical(j.label) == first]
        for joint in joints:
            chosen.joint_values[joint.name] = open_value(joint, state, rng)
