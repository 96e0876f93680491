"""Loading the knowledge base from its data files, plus the queries other stages need.

The data lives in JSON (``anomalygen/data/knowledge/``) so it can be reviewed and extended without
touching code; this module validates it once, caches it, and answers questions such as "which
catalogue objects can be the hazard of this class?" from the same data the predicates use.
"""

from __future__ import annotations

import functools
import json
from pathlib import Path
from typing import Any

from anomalygen.knowledge.models import (
    DATA_DIR,
    KNOWLEDGE_DIR,
    PROPERTIES,
    RECIPE_ARGS,
    ROOMS,
    HazardClass,
    ObjectInfo,
    RoleProfile,
)
from anomalygen.schema import (
    LATCHING_PROPERTY,
    OTHER_SLOT,
    SUPPORT_KINDS,
    HazardCategory,
    Placement,
    PredicateCall,
)


def _data(name: str) -> Any:
    return json.loads((KNOWLEDGE_DIR / name).read_text(encoding="utf-8"))


def vocabulary() -> dict[str, Any]:
    return json.loads((DATA_DIR / "vocabulary.json").read_text(encoding="utf-8"))


class KnowledgeBase:
    """Hazard classes, object knowledge and role profiles, validated and indexed."""

    def __init__(self, hazard_classes: list[HazardClass], objects: list[ObjectInfo], roles: list[RoleProfile],
                 lookalike_groups: list[list[str]] | None = None):
        self.hazard_classes: dict[str, HazardClass] = {hc.id: hc for hc in hazard_classes}
        self.objects: dict[str, ObjectInfo] = {o.name: o for o in objects}
        self.roles: dict[str, RoleProfile] = {r.id: r for r in roles}
        #: groups of objects a perceiver can mistake for one another (``lookalikes.json``)
        self.lookalike_groups: list[list[str]] = [list(g) for g in lookalike_groups or []]
        self._candidates: dict[tuple[str, str], list[str]] = {}
        self._child_classes: dict[str, list[HazardClass]] = {}

    def add_composed(self, composed: list[HazardClass]) -> None:
        """Add the classes composed from mechanisms: a legacy row only tags its hand-written class with
        its composition; every other row is a class of its own, with ``near:{other}``-style placements
        spelled out over the objects that can fill the related variable."""
        self._child_classes.clear()
        for hc in composed:
            own = self.hazard_classes.get(hc.id)
            if hc.composition is not None and hc.composition.legacy and own is not None:
                self.hazard_classes[hc.id] = own.model_copy(update={"composition": hc.composition})
                continue
            self.hazard_classes[hc.id] = hc
            if any(p.other == OTHER_SLOT for p in hc.placements):
                self.hazard_classes[hc.id] = hc.model_copy(update={"placements": self._spelled_placements(hc)})

    def _spelled_placements(self, hc: HazardClass) -> list[Placement]:
        from anomalygen.knowledge.mechanisms import load_mechanisms

        place = load_mechanisms().places[hc.composition.place]
        var = place.relation.variable if place.relation else None
        others = self.static_candidates(hc, var) if var else []
        out: list[Placement] = []
        for p in hc.placements:
            out += [p.filled(o) for o in others] if p.other == OTHER_SLOT else [p]
        return out

    # ------------------------------------------------------------------ simple views
    @property
    def targets(self) -> list[str]:
        return [n for n, o in self.objects.items() if o.kind == "target"]

    @property
    def household(self) -> list[str]:
        return [n for n, o in self.objects.items() if o.kind == "household"]

    def paper_classes(self) -> list[HazardClass]:
        return [hc for hc in self.hazard_classes.values() if hc.paper_class]

    def classes_in(self, category: HazardCategory | str) -> list[HazardClass]:
        return [hc for hc in self.hazard_classes.values() if hc.category == category]

    def properties_of(self, name: str) -> list[str]:
        """Perceived properties of a catalogue object (what the scene builder puts in GraphObject.properties)."""
        info = self.objects.get(name)
        return list(info.properties) if info else []

    def lookalikes(self, name: str) -> list[str]:
        """The other members of ``name``'s look-alike group (empty when it has none)."""
        group = next((g for g in self.lookalike_groups if name in g), [])
        return [n for n in group if n != name]

    def benign_objects(self) -> list[str]:
        """Household objects with no hazard-relevant property: safe clutter that triggers no class."""
        from anomalygen.knowledge.models import HAZARD_PROPERTIES

        blocked = HAZARD_PROPERTIES | {"furniture", "appliance", "container"}
        return [n for n, o in self.objects.items() if o.kind == "household" and not (set(o.properties) & blocked)]

    # ------------------------------------------------------------------ class queries
    def static_candidates(self, hc: HazardClass, variable: str) -> list[str]:
        """Catalogue names that satisfy every object-intrinsic precondition on ``variable``.

        Intrinsic means decidable from the object alone (``has_property``, ``category_is``); the
        situational ones (height, joints, walkway) are what a scenario sets up.
        """
        key = (hc.id, variable)
        if key not in self._candidates or hc is not self.hazard_classes.get(hc.id):
            calls = [
                c
                for c in hc.preconditions
                if c.name in ("has_property", "category_is", "joint_open", "joint_closed") and c.args.get("object") == variable
            ]
            found = [name for name, info in self.objects.items() if all(_static_holds(c, info) for c in calls)]
            if hc is not self.hazard_classes.get(hc.id):
                return found  # a class built outside this knowledge base: do not cache
            self._candidates[key] = found
        return list(self._candidates[key])

    def hazard_candidates(self, hc: HazardClass) -> list[str]:
        """Catalogue objects that can be the hazard of ``hc`` (the curated list, if any, filtered)."""
        able = self.static_candidates(hc, hc.hazard_variable)
        if hc.hazard_objects:
            return [n for n in hc.hazard_objects if n in able]
        return able

    def containers_for(self, hc: HazardClass, obj: str) -> list[str]:
        """Where ``obj`` can be put away for class ``hc``: class defaults the object fits, in class order.

        When the stored object is a small child's hazard as well (a knife, a cleaner: ``stores_a_child_hazard``)
        and the class names no kind that latches, the latching kinds the child's classes store it in
        follow: a knife put away low in a box a toddler opens fires the child's class, so the referee
        rightly rejects that fix, and the builder and planner must have a latching one to use."""
        kinds = self._own_containers(hc, obj)
        if not kinds or any(self.latches(k) for k in kinds) or not self.stores_a_child_hazard(hc, obj):
            return kinds
        extra = [k for g in self._child_classes_of(obj) for k in self._own_containers(g, obj) if self.latches(k)]
        return [*kinds, *dict.fromkeys(k for k in extra if k not in kinds)]

    def _own_containers(self, hc: HazardClass, obj: str) -> list[str]:
        if not hc.default_containers:
            return []
        own = self.objects[obj].containers if obj in self.objects else []
        both = [c for c in hc.default_containers if c in own]
        return both or list(hc.default_containers)

    def _child_classes_of(self, obj: str) -> list[HazardClass]:
        """The classes guarding a small child that ``obj`` can be the hazard of."""
        if obj not in self._child_classes:
            self._child_classes[obj] = [g for g in self.hazard_classes.values()
                                        if self.guards_a_child(g) and obj in self.hazard_candidates(g)]
        return self._child_classes[obj]

    def stores_a_child_hazard(self, hc: HazardClass, obj: str) -> bool:
        """Must ``hc``'s fix shut ``obj`` away from a toddler: the class guards a child, or ``obj`` is the
        hazard of a class that does (then a box or cupboard the child opens is no place for it)."""
        return self.guards_a_child(hc) or bool(self._child_classes_of(obj))

    def guards_a_child(self, hc: HazardClass) -> bool:
        """Is the class's danger a small child reaching the object (a ``child_reachable`` precondition)?"""
        return any(c.name == "child_reachable" and not c.negate for c in hc.preconditions)

    def latches(self, name: str) -> bool:
        """Does a container of this kind latch shut (a toddler opens a box or a cupboard, not a safe)?"""
        return LATCHING_PROPERTY in self.properties_of(name)

    def latching_containers_for(self, hc: HazardClass, obj: str) -> list[str]:
        """The kinds of ``containers_for`` that latch, in class order."""
        return [k for k in self.containers_for(hc, obj) if self.latches(k)]

    def safe_containers_for(self, hc: HazardClass, obj: str) -> list[str]:
        """``containers_for``, kept to the kinds that latch when the stored object is a child's hazard
        and any of them is on the list: storing a knife in a box a toddler opens does not end its hazard."""
        kinds = self.containers_for(hc, obj)
        if not self.stores_a_child_hazard(hc, obj):
            return kinds
        return self.latching_containers_for(hc, obj) or kinds

    def placements_for(self, hc: HazardClass, obj: str) -> list[Placement]:
        """Class placements that are plausible for ``obj`` given where it usually rests: on or at the
        edge of a support kind it rests on, inside something it is kept in (or the fridge), or on or
        near another object."""
        info = self.objects.get(obj)
        out = []
        for p in hc.placements:
            if p.relation == "inside":
                if info is None or p.other in info.containers or p.other == "Refrigerator":
                    out.append(p)
            elif info is None or not info.supports or p.support in info.supports or p.other is not None:
                out.append(p)
        return out or list(hc.placements)

    def articulation_part(self, hc: HazardClass, obj: str) -> str | None:
        """The concrete joint label of ``obj`` that ``hc``'s articulation is about (first alternative it has)."""
        if hc.articulation is None:
            return None
        info = self.objects.get(obj)
        labels = [p.label for p in info.parts] if info else []
        alts = hc.articulation.part.split("|")
        return next((a for a in alts if a in labels), None)

    # ------------------------------------------------------------------ consistency
    def class_problems(self, hc: HazardClass) -> list[str]:
        """What is wrong with one class against this knowledge base and the vocabulary (empty: usable).

        Also the check a class an LLM proposes must pass before it is used (``brainstorm/new_class.py``)."""
        from anomalygen.knowledge.predicates import PREDICATES

        out: list[str] = []
        names = set(self.objects)
        voc = vocabulary()
        where = f"class {hc.id}"
        if not hc.preconditions or not hc.recipe or not hc.success:
            out.append(f"{where}: needs preconditions, recipe and success")
        declared = set(hc.variables)
        if hc.hazard_variable not in declared:
            out.append(f"{where}: hazard_variable {hc.hazard_variable} not declared")
        for call in [*hc.preconditions, *hc.success]:
            out += [f"{where}: {m}" for m in _call_problems(call, PREDICATES, names, declared)]
        for step in hc.recipe:
            allowed = RECIPE_ARGS[step.action]
            if set(step.args) - set(allowed) or "object" not in step.args:
                out.append(f"{where}: recipe step {step} has wrong arguments (wants {allowed})")
            for v in step.args.values():
                if v.startswith("$") and v not in declared:
                    out.append(f"{where}: recipe uses undeclared variable {v}")
        for p in hc.placements:
            if p.other is not None and p.other not in names:
                out.append(f"{where}: unknown placement {p}")
        out += [f"{where}: unknown container {c}" for c in hc.default_containers if c not in names]
        out += [f"{where}: unknown support {c}" for c in hc.default_supports if c not in names]
        out += [f"{where}: target {t} is not a target category" for t in hc.target_assets if t not in voc["targets"]]
        out += [f"{where}: unknown room {r}" for r in hc.rooms if r not in ROOMS]
        if "$container" in declared and not hc.default_containers:
            out.append(f"{where}: uses $container but has no default_containers")
        if "$support" in declared and not hc.default_supports:
            out.append(f"{where}: uses $support but has no default_supports")
        bad = [n for n in hc.hazard_objects if n not in self.static_candidates(hc, hc.hazard_variable)]
        if bad:
            out.append(f"{where}: hazard_objects {bad} do not meet the class's intrinsic preconditions")
        if not self.hazard_candidates(hc):
            out.append(f"{where}: no catalogue object can be its hazard")
        return out

    def problems(self) -> list[str]:
        """Every broken reference in the data; empty when the knowledge base is consistent."""

        out: list[str] = []
        names = set(self.objects)
        voc = vocabulary()
        missing = (set(voc["targets"]) | set(voc["household"])) - names
        if missing:
            out.append(f"vocabulary names without ObjectInfo: {sorted(missing)}")
        for o in self.objects.values():
            out += [f"object {o.name}: unknown property {p}" for p in o.properties if p not in PROPERTIES]
            out += [f"object {o.name}: unknown room {r}" for r in o.rooms if r not in ROOMS]
            out += [f"object {o.name}: unknown container {c}" for c in o.containers if c not in names]
            out += [f"object {o.name}: unknown support {s}" for s in o.supports if s not in SUPPORT_KINDS]
            lo, hi = o.size_range
            if not 0 < lo <= hi:
                out.append(f"object {o.name}: bad size_range {o.size_range}")
        for hc in self.hazard_classes.values():
            out += self.class_problems(hc)
        from anomalygen.knowledge.mechanisms import load_mechanisms, mechanism_problems

        out += mechanism_problems(load_mechanisms(), names)
        grouped = [n for g in self.lookalike_groups for n in g]
        out += [f"look-alikes: unknown object {n}" for n in grouped if n not in names]
        out += [f"look-alikes: {n} is in more than one group" for n in sorted({n for n in grouped if grouped.count(n) > 1})]
        for r in self.roles.values():
            out += [f"role {r.id}: unknown class {c}" for c in r.class_interests if c not in self.hazard_classes]
            out += [f"role {r.id}: unknown object {o}" for o in r.object_interests if o not in names]
            out += [f"role {r.id}: unknown room {x}" for x in r.room_interests if x not in ROOMS]
        return out


def _static_holds(call: PredicateCall, info: ObjectInfo) -> bool:
    if call.name in ("joint_open", "joint_closed"):  # the object must at least have such a part
        labels = str(call.args.get("label", "*")).split("|")
        return "*" in labels or any(p.label in labels for p in info.parts)
    alts = [a for a in str(call.args.get("property" if call.name == "has_property" else "category", "")).split("|") if a]
    if call.name == "has_property":
        holds = any(a in info.properties for a in alts)
    else:
        holds = info.name in alts
    return holds != call.negate


def _call_problems(call: PredicateCall, predicates, names: set[str], declared: set[str]) -> list[str]:
    spec = predicates.get(call.name)
    if spec is None:
        return [f"unknown predicate {call.name}"]
    out = [f"{call.name}: unknown argument {a}" for a in call.args if a not in spec.args]
    for v in call.args.values():
        if isinstance(v, str) and v.startswith("$") and v not in declared:
            out.append(f"{call.name}: undeclared variable {v}")
    if call.name == "has_property":
        out += [f"unknown property {p}" for p in str(call.args.get("property", "")).split("|") if p not in PROPERTIES]
    if call.name == "category_is":
        out += [f"unknown category {c}" for c in str(call.args.get("category", "")).split("|") if c not in names]
    if call.name == "room_is":
        out += [f"unknown room {r}" for r in str(call.args.get("room", "")).split("|") if r not in ROOMS]
    from anomalygen.knowledge.predicates import parse_flag

    if "walls_separate" in call.args and parse_flag(call.args["walls_separate"]) is None:
        out.append(f"{call.name}: walls_separate must be 'true' or 'false', not {call.args['walls_separate']!r}")
    return out


#: In a run folder: the classes an LLM proposed for that run (validated), used like any other class.
RUN_CLASSES = Path("knowledge") / "classes.json"


def add_run_classes(root: str | Path) -> list[str]:
    """Add the classes a run folder carries to this process's knowledge base; returns the new ids.

    Every process that opens the run (each stage, each worker) calls this through ``RunFolder``, so
    a class proposed while brainstorming is known to the builder, the detector, the planner and the
    referee. A class id already known is left as it is."""
    path = Path(root) / RUN_CLASSES
    if not path.is_file():
        return []
    kb = load_kb()
    added = []
    for raw in json.loads(path.read_text(encoding="utf-8")).get("classes", []):
        hc = HazardClass.model_validate(raw)
        if hc.id not in kb.hazard_classes:
            kb.hazard_classes[hc.id] = hc
            added.append(hc.id)
    return added


@functools.cache
def load_kb() -> KnowledgeBase:
    """The bundled knowledge base (validated, cached for the process)."""
    classes = [HazardClass.model_validate(c) for c in _data("hazard_classes.json")["classes"]]
    objects = [ObjectInfo.model_validate({"name": n, **o}) for n, o in _data("objects.json")["objects"].items()]
    roles = [RoleProfile.model_validate(r) for r in _data("roles.json")["roles"]]
    kb = KnowledgeBase(classes, objects, roles, _data("lookalikes.json")["groups"])
    from anomalygen.knowledge.mechanisms import composed_classes

    kb.add_composed(composed_classes())
    return kb
