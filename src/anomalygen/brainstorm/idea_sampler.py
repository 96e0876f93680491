"""The offline engine's idea sampler: draw a concrete, buildable Idea from an agent's interests, and
recombine other agents' ideas.

This is not name grounding. Resolving the loose names an LLM or a person writes into knowledge-base
names is ``knowledge/grounding.py``, shared by every engine; nothing here reads a name someone wrote.
Every choice is drawn from the knowledge base (objects that really have the class's properties,
placements and containers the class allows), so an Idea is valid by construction: its objects are
in the catalogue and its hazard's preconditions can be set up by the scene builder.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TypeVar

import numpy as np

from anomalygen.brainstorm.describe import people_for, person_fits
from anomalygen.brainstorm.idea import Idea, secondary_variables
from anomalygen.knowledge import HazardClass, KnowledgeBase, RoleProfile
from anomalygen.knowledge.households import load_households
from anomalygen.schema import Placement

#: Weight ratio between successive options of a typicality-ordered list for the role-less generator.
TYPICAL_DECAY = 0.35
#: Draws a fresh idea may take before giving up: a draw is retried when no room holds its fixtures.
FRESH_TRIES = 200
T = TypeVar("T")


def weighted(rng: np.random.Generator, options: list[T], weights: dict[T, float] | None = None) -> T:
    if not options:
        raise ValueError("nothing to choose from")
    w = np.array([max(1e-6, (weights or {}).get(o, 1.0)) for o in options], dtype=float)
    return options[int(rng.choice(len(options), p=w / w.sum()))]


_CLASS_TARGETS: dict[tuple[int, str], list[str]] = {}


def class_targets(kb: KnowledgeBase, hc: HazardClass) -> list[str]:
    """Target categories a proposal of ``hc`` can be built around: named ones, hazards, containers."""
    key = (id(kb), hc.id)
    if key not in _CLASS_TARGETS:
        _CLASS_TARGETS[key] = _class_targets(kb, hc)
    return _CLASS_TARGETS[key]


def _class_targets(kb: KnowledgeBase, hc: HazardClass) -> list[str]:
    targets = set(kb.targets)
    out = list(hc.target_assets)
    drawn = [h for h in kb.hazard_candidates(hc) if h not in hc.not_drawn]  # a kettle by the sink is not drawn yet
    for name in [*drawn, *hc.default_containers, *hc.default_supports]:
        if name in targets and name not in out:
            out.append(name)
    # a class whose preconditions name the target's category (the microwave metal is left in) is built
    # around that category only: a table as the target of such a scene cannot be built
    pinned = {c for call in hc.preconditions if call.name == "category_is" and not call.negate
              and call.args.get("object") == "$target" for c in str(call.args.get("category", "")).split("|")}
    out = [t for t in out if t in pinned] or out if pinned else out
    if hc.about_target:  # the target is the object at fault: only those that can be
        from anomalygen.brainstorm.drawable import hazards_for

        can = set(hazards_for(kb, hc))
        out = [t for t in out if t in can]
    return out


def classes_for_target(kb: KnowledgeBase, target: str) -> list[HazardClass]:
    """The classes a proposal around ``target`` can be of, among those that can be built today."""
    from anomalygen.brainstorm.drawable import drawable

    return [hc for hc in kb.hazard_classes.values() if target in class_targets(kb, hc) and drawable(kb, hc)]


def usable_targets(kb: KnowledgeBase) -> list[str]:
    return [t for t in kb.targets if classes_for_target(kb, t)]


def _scene_of(room: str, placement: Placement, names) -> dict:
    """What ``person_fits`` looks at: the room and every name in the scene, the placement's included."""
    return {"room": room, "names": [*names, placement.support, placement.other]}


def idea_scene(idea: Idea) -> dict:
    return _scene_of(idea.room, idea.placement, [idea.hazard, idea.container, idea.support, *idea.co_objects])


class IdeaSampler:
    """Makes ideas for one agent (a role, or None for the plain, role-less generator)."""

    def __init__(self, kb: KnowledgeBase, role: RoleProfile | None, *, targets: list[str] | None = None, rich: bool = True):
        self.kb = kb
        self.role = role
        self.rich = rich  # role-play modes add people and co-objects
        self.targets = [t for t in (targets or usable_targets(kb)) if classes_for_target(kb, t)]
        #: With the whole catalogue open, agents think hazard-first (every class gets a fair share of
        #: targets); when a protocol hands them a fixed set of targets (the ablation), they pick
        #: among those by interest, as the paper's agents pick from the assets they are given.
        self.hazard_first = targets is None
        # Co-objects: safe clutter that normally rests on furniture. Things that live on the floor
        # (shoes, balls, books) would become a second, tripping, hazard wherever a scene puts them.
        self.benign = [b for b in kb.benign_objects() if "floor" not in kb.objects[b].supports]
        #: How often the group has already used a class/object/room/placement (set by the engine in
        #: brainstorm mode, where agents see the shared pool): choices lean away from repeats.
        self.seen: dict[str | Placement, int] = {}

    # ---------------------------------------------------------------- weights
    def _w(self, kind: str, options: list | None = None) -> dict | None:
        if self.role is None and options is not None and kind != "object_target":
            # No persona and no group: fall back on the most typical choice (lists are ordered by
            # typicality in the knowledge base), as a plainly prompted generator tends to.
            return {o: TYPICAL_DECAY**rank for rank, o in enumerate(options)}
        base = getattr(self.role, f"{kind}_interests", None) if self.role is not None else None
        if not self.seen or options is None:
            return base
        return {o: (base or {}).get(o, 1.0) / (1.0 + self.seen.get(o, 0)) for o in options}

    def _class_weights(self, classes: list[HazardClass]) -> dict[str, float]:
        if self.role is None:
            return {hc.id: TYPICAL_DECAY**rank for rank, hc in enumerate(classes)}
        base = self._w("class") or {}
        return {
            hc.id: base.get(hc.id, 1.0) * (2.0 if hc.paper_class else 1.0) / (1.0 + self.seen.get(hc.id, 0))
            for hc in classes
        }

    # ---------------------------------------------------------------- fresh ideas
    def pick_target(self, rng: np.random.Generator) -> str:
        if self.role is None:
            return weighted(rng, self.targets)
        if not self.hazard_first:
            return weighted(rng, self.targets, self._w("object", self.targets))
        # Interest in an object times the interest in the hazards it can be part of, each hazard's
        # mass shared among its targets: an open fridge (one target) is as thinkable as a fragile
        # object near an edge (many targets).
        objects = self._w("object", self.targets) or {}
        classes = self._class_weights(list(self.kb.hazard_classes.values()))
        weights = {
            t: objects.get(t, 1.0)
            * sum(classes[hc.id] / len(class_targets(self.kb, hc)) for hc in classes_for_target(self.kb, t))
            for t in self.targets
        }
        return weighted(rng, self.targets, weights)

    def pick_class(self, rng: np.random.Generator, target: str) -> HazardClass:
        options = classes_for_target(self.kb, target)
        chosen = weighted(rng, [hc.id for hc in options], self._class_weights(options))
        return self.kb.hazard_classes[chosen]

    def fresh(self, rng: np.random.Generator, *, agent: str | None, agent_index: int, round_: int) -> Idea:
        for _ in range(FRESH_TRIES):
            target = self.pick_target(rng)
            hc = self.pick_class(rng, target)
            idea = self.idea_for(rng, hc, target, agent=agent, agent_index=agent_index, round_=round_)
            if idea is not None:
                return idea
        raise RuntimeError(f"no plausible home for any of {FRESH_TRIES} draws: check data/knowledge/households.json")

    def idea_for(
        self,
        rng: np.random.Generator,
        hc: HazardClass,
        target: str,
        *,
        agent: str | None,
        agent_index: int,
        round_: int,
        avoid_hazard: str | None = None,
    ) -> Idea | None:
        from anomalygen.brainstorm.drawable import (
            containers_for,
            harmless_first,
            hazards_for,
            placements_for,
            relation_variable,
        )

        kb = self.kb
        homes = load_households()
        # an object is drawn only in a room it is found in: a frying pan in a kitchen, a razor in a
        # bathroom (its rooms in households.json for a fixture, objects.json for anything else)
        candidates = [c for c in hazards_for(kb, hc) if self.usual_rooms(hc, c)]
        if not (self.usual_rooms(hc, target) if hc.about_target else candidates):
            return None
        if hc.about_target:
            # the class is about the target itself (its door is open, it is on): a safe named beside a
            # table would be built as the table's open drawer, so the object at fault is the target
            # (class_targets offers only targets that can be)
            hazard = target
        elif target in candidates and (avoid_hazard != target) and (len(candidates) == 1 or rng.random() < 0.7):
            hazard = target
        else:
            pool = [c for c in candidates if c != avoid_hazard] or candidates
            hazard = weighted(rng, pool, self._w("object", pool))
        placements = placements_for(kb, hc, hazard)
        parents = harmless_first(kb, [p.other for p in placements if p.other is not None])
        placements = [p for p in placements if p.other is None or p.other in parents]
        # the fix the text promises must end the hazard, and the hazard must fit in
        containers = containers_for(kb, hc, hazard) if hc.default_containers else kb.safe_containers_for(hc, hazard)
        related = relation_variable(hc)
        secondary = {var: harmless_first(kb, self.kb.static_candidates(hc, var))
                     for var in secondary_variables(hc) if not (var == related)}
        # a plausible home: every fixture the idea names belongs in its room (data/knowledge/households.json)
        usual = self.usual_rooms(hc, hazard)

        def rooms_with(p: Placement) -> list[str]:
            rooms = homes.rooms_for([hazard, p.support, p.other], usual)
            if p.other is not None:
                rooms = [r for r in rooms if self.found_in(p.other, r)]  # a blanket is not kept in a bathroom
            if hc.default_supports:
                rooms = [r for r in rooms if any(homes.belongs(b, r) for b in hc.default_supports)]
            if containers:
                rooms = [r for r in rooms if any(homes.belongs(c, r) for c in containers)]
            return [r for r in rooms if all(any(self.found_in(c, r) for c in opts) for opts in secondary.values() if opts)]

        placements = [p for p in placements if rooms_with(p)]
        if not placements:  # no room holds every fixture this hazard needs: not a home anyone lives in
            return None
        placement = weighted(rng, placements, self._w("placement", placements))
        rooms = rooms_with(placement)
        room = weighted(rng, rooms, self._w("room", rooms))
        containers = [c for c in containers if homes.belongs(c, room)]
        container = (target if target in containers else weighted(rng, containers)) if containers else None
        support = None
        if hc.default_supports:
            supports = [b for b in hc.default_supports if homes.belongs(b, room)]
            support = target if target in supports else weighted(rng, supports)
        co: list[str] = []
        for var in secondary_variables(hc):
            if var == related and placement.other is not None:  # the burner the towel is on: the placement's object
                co.append(placement.other)
            else:
                options = secondary.get(var) or harmless_first(kb, self.kb.static_candidates(hc, var))
                co.append(weighted(rng, [c for c in options if self.found_in(c, room)] or options))
        # the person at risk fits the scene: the cook in a kitchen, a child in the bath beside a bathtub
        people = people_for(hc, _scene_of(room, placement, [hazard, container, support, *co]))
        person = people[int(rng.integers(len(people)))] if (self.rich and people) else hc.at_risk
        if self.rich:
            fitting = [b for b in self.benign if room in kb.objects[b].rooms and b not in co]
            for _ in range(int(rng.integers(0, 3))):
                if fitting:
                    pick = weighted(rng, fitting)
                    fitting.remove(pick)
                    co.append(pick)
        return Idea(
            class_id=hc.id,
            target=target,
            hazard=hazard,
            placement=placement,
            room=room,
            person=person,
            container=container,
            support=support,
            co_objects=tuple(co),
            agent=agent,
            agent_index=agent_index,
            round=round_,
        )

    def found_in(self, obj: str, room: str) -> bool:
        """Is ``obj`` found in ``room``: a fixture where it belongs, anything else where it is kept
        (a toaster in a kitchen, not a bathroom)."""
        homes = load_households()
        if obj in homes.fixtures:
            return homes.belongs(obj, room)
        rooms = self.kb.objects[obj].rooms if obj in self.kb.objects else ()
        return not rooms or room in rooms

    def usual_rooms(self, hc: HazardClass, obj: str) -> list[str]:
        """The class's rooms that the object is found in (none: the two never meet in a home, as a
        frying pan and a living room's low table do not)."""
        return [r for r in hc.rooms if self.found_in(obj, r)]

    # ---------------------------------------------------------------- recombination
    def recombine(
        self,
        rng: np.random.Generator,
        sources: list[tuple[str, Idea]],
        *,
        agent: str | None,
        agent_index: int,
        round_: int,
        tries: int = 8,
    ) -> Idea | None:
        """A new idea that borrows one or two aspects from other agents' ideas (``(id, idea)`` pairs).

        The borrowed aspect is kept; everything else comes from this agent's own interests, so the
        result mixes another perspective with its own rather than copying.
        """
        if not sources:
            return None
        for _ in range(tries):
            n_src = 1 if len(sources) == 1 or rng.random() < 0.6 else 2
            picks = rng.choice(len(sources), size=n_src, replace=False)
            chosen = [sources[int(i)] for i in picks]
            aspects = list(rng.permutation(["mechanism", "location", "co_objects", "person_at_risk"]))
            plan: list[tuple[str, str, Idea]] = []
            for sid, src in chosen:
                for aspect in aspects:
                    if aspect in [p[1] for p in plan]:
                        continue
                    if aspect == "co_objects" and not [c for c in src.co_objects if c in self.benign]:
                        continue
                    plan.append((sid, str(aspect), src))
                    break
            # Whatever is not borrowed should move away from the sources: a new idea, not a copy.
            saved = self.seen
            self.seen = dict(saved)
            for _, src in chosen:
                for key in (src.class_id, src.hazard, src.target, src.room, src.placement):
                    self.seen[key] = self.seen.get(key, 0) + 2
            try:
                idea = self._apply(rng, plan, agent=agent, agent_index=agent_index, round_=round_)
            finally:
                self.seen = saved
            if idea is not None and all(idea.key() != src.key() for _, src in chosen):
                return idea
        return None

    def _apply(self, rng, plan, *, agent, agent_index, round_) -> Idea | None:
        from anomalygen.brainstorm.drawable import placements_for, relation_variable

        kb = self.kb
        mech = next((src for _, a, src in plan if a == "mechanism"), None)
        if mech is not None:
            hc = kb.hazard_classes[mech.class_id]
            targets = [t for t in class_targets(kb, hc) if t in self.targets] or class_targets(kb, hc)
            target = weighted(rng, targets, self._w("object", targets))
            idea = self.idea_for(rng, hc, target, agent=agent, agent_index=agent_index, round_=round_, avoid_hazard=mech.hazard)
            if idea is None:
                return None
        else:
            idea = self.fresh(rng, agent=agent, agent_index=agent_index, round_=round_)
        hc = kb.hazard_classes[idea.class_id]
        for _, aspect, src in plan:
            if aspect == "location":
                rooms_ok = src.room in self.usual_rooms(hc, idea.hazard) and not load_households().misplaced(
                    replace(idea, room=src.room))
                place_ok = src.placement in placements_for(kb, hc, idea.hazard) and not relation_variable(hc)
                if not (rooms_ok or place_ok):
                    return None
                idea = replace(idea, room=src.room if rooms_ok else idea.room, placement=src.placement if place_ok else idea.placement)
            elif aspect == "co_objects":
                own_needed = [idea.co_objects[i] for i in range(len(secondary_variables(hc)))]
                borrowed = [c for c in src.co_objects if c in self.benign and c not in own_needed]
                extra = [c for c in idea.co_objects[len(own_needed):] if c not in borrowed][:1]
                idea = replace(idea, co_objects=tuple(own_needed + borrowed + extra))
            elif aspect == "person_at_risk":
                if src.person not in hc.people:
                    return None
                idea = replace(idea, person=src.person)
        if load_households().misplaced(idea):  # a borrowed place or room that this idea's fixtures do not fit
            return None
        # clutter borrowed from another room, or left behind by a borrowed room, stays only where it is kept
        needed = len(secondary_variables(hc))
        idea = replace(idea, co_objects=idea.co_objects[:needed]
                       + tuple(c for c in idea.co_objects[needed:] if self.found_in(c, idea.room)))
        if idea.person in hc.people and not person_fits(idea.person, **idea_scene(idea)):
            return None  # a borrowed room where this person makes no sense (the cook in a bedroom)
        return replace(
            idea,
            builds_on=tuple(dict.fromkeys(sid for sid, _, _ in plan)),
            borrowed=tuple(a for _, a, _ in plan),
        )
