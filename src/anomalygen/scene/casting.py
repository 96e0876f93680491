"""Casting the scene: which objects it holds and which role each plays, before anything is placed.

``select_objects`` chooses an asset for every role the task needs (target, hazard, the object it sits
in or on, container, ``$support``, co-objects) and who plays ``$hazard``; ``set_initial_joints`` sets the
joint states that make the hazard real (or safe, for a hazard-free scene); ``bind_roles`` maps the
class's role variables to instance names once the scene is placed. Clutter names are drawn here too.
Each asset is chosen, sized and checked in ``asset_choice.py``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from anomalygen.errors import ItemFailed
from anomalygen.knowledge import load_kb
from anomalygen.scene import asset_choice
from anomalygen.scene.asset_choice import container_room
from anomalygen.scene.instances import instance_name
from anomalygen.scene.layout import Placed
from anomalygen.scene.set_states import set_initial_states
from anomalygen.schema import ObjectRole, Placement, TaskProposal, part_labels

MAX_AUX = 3
CONTAINER_REDRAWS = 4  # other container sizes drawn before a smaller hazard is tried
CLUTTER_MAX_SIZE = 0.3
SAFE_STATE = {"open": "closed", "on": "off"}  # a part's state in a hazard-free scene
OPPOSITE_STATE = {"open": "closed", "closed": "open", "on": "off", "off": "on"}


def is_dressing(kb, name: str) -> bool:
    """Can ``name`` dress a scene as clutter? Small household things with no hazard property, so a
    decoration never becomes a second hazard (also the filter for the LLM engine's auxiliaries)."""
    from anomalygen.knowledge.models import HAZARD_PROPERTIES

    info = kb.objects.get(name)
    if info is None or info.kind != "household":
        return False
    if set(info.properties) & (HAZARD_PROPERTIES | {"furniture", "appliance"}):
        return False
    return info.size_range[0] <= CLUTTER_MAX_SIZE


def clutter_names(kb, exclude: set[str], rng, n: int) -> list[str]:
    names = [name for name in asset_choice.catalogue_names() if name not in exclude and is_dressing(kb, name)]
    if not names or n <= 0:
        return []
    idx = rng.choice(len(names), size=min(n, len(names)), replace=False)
    return [names[i] for i in sorted(idx)]


@dataclass
class Selection:
    """The objects chosen for one task, by role, before anything is placed (``select_objects``)."""

    task: TaskProposal
    rng: np.random.Generator
    kb: object
    hc: object  # the task's HazardClass, or None
    used: set[str] = field(default_factory=set)
    by_catalogue: dict[str, asset_choice.Chosen] = field(default_factory=dict)
    target: asset_choice.Chosen | None = None
    parent: asset_choice.Chosen | None = None
    hazard: asset_choice.Chosen | None = None
    hazard_var: asset_choice.Chosen | None = None  # the object bound to $hazard
    container: asset_choice.Chosen | None = None
    support_var: asset_choice.Chosen | None = None
    aux: list[asset_choice.Chosen] = field(default_factory=list)
    hazard_is_target: bool = False
    hints: object | None = None  # scene/hints.py: sizes, positions and auxiliaries from the LLM engine
    hazard_free: bool = False  # build the task's hazard in its safe state (scene/mix.py)
    real_assets: bool = True  # draw a category's real (packaged) models where it has any (build.real_assets)
    repair: int = 0  # the build attempt: a repair draws the object at fault from the small end of its range

    @property
    def placement(self) -> Placement:
        """Where the scenario puts the hazard object."""
        return self.task.scenario.placement

    @property
    def parent_raw(self) -> str | None:
        """The object the placement names as written (the stove the towel is on), if any."""
        return self.placement.other

    @property
    def variables(self) -> set[str]:
        return set(self.hc.variables) if self.hc is not None else set()

    def choose(self, raw: str, role: ObjectRole, *, cap=None, rank=False, room_for=None,
               stores=None) -> asset_choice.Chosen:
        """The asset for a name (one per catalogue category: a second mention reuses it).

        ``room_for``: the least size of what will be put inside it (a real model with too small an
        interior gives way to the procedural one). ``stores``: the least size of what the fix puts
        away in it (a smaller container is drawn again)."""
        cat = asset_choice.resolve_name(raw)
        if cat in self.by_catalogue:
            return self.by_catalogue[cat]
        want = self.hints.size_for(cat) if self.hints is not None else None
        asset = asset_choice.pick_asset(cat, role=role, kb=self.kb, task=self.task, hc=self.hc, rng=self.rng,
                                        cap=cap, rank=rank, size=want, real=self.real_assets, room_for=room_for,
                                        stores=stores)
        if want is not None and abs(asset.size - want) > 1e-3:
            self.hints.note(f"size:{cat}", f"size {want:.3f} m does not fit the generator's range or the space "
                            f"available; built at {asset.size:.3f} m", value=want, limit=round(float(asset.size), 4))
        ch = asset_choice.Chosen(instance_name(cat, self.used), cat, role, asset)
        self.by_catalogue[cat] = ch
        return ch

    def forget(self, ch: asset_choice.Chosen) -> None:
        """Drop a choice so the next ``choose`` of its category draws again."""
        self.by_catalogue.pop(ch.catalogue, None)
        self.used.discard(ch.name)


def _repair_cap(sel: Selection, raw: str, cap: float | None) -> float | None:
    """The largest size a repair draws the object at fault in: the lower ``1 / (repair + 1)**2`` of its
    range. Most failed attempts are a thing too big for where it goes (a 2 m cord on a table, a
    stair tread or between furniture); drawing it again at random fails the same way."""
    if sel.repair <= 0:
        return cap
    lo, hi = asset_choice.size_bounds(sel.kb, asset_choice.resolve_name(raw))
    shrunk = lo + (hi - lo) / (sel.repair + 1) ** 2
    return shrunk if cap is None else min(cap, shrunk)


def select_objects(task: TaskProposal, rng, hints=None, *, real_assets: bool = True, repair: int = 0) -> Selection:
    """Choose an asset for every role the task needs (target, hazard, container, supports, co-objects).

    ``hints`` (scene/hints.py, from the LLM engine) supply sizes, floor positions and the auxiliary
    objects instead of the random draws; every correction is noted in them or in the layout.
    ``real_assets`` False builds every object from the procedural generators (a comparison run).
    ``repair``: the attempt number; a repair draws the object at fault smaller (``_repair_cap``)."""
    kb = load_kb()
    sc = task.scenario
    sel = Selection(task, rng, kb, kb.hazard_classes.get(task.hazard_class), hints=hints, real_assets=real_assets,
                    repair=repair)
    relation, parent_raw = sel.placement.relation, sel.parent_raw
    hc, variables = sel.hc, sel.variables
    sel.hazard_is_target = asset_choice.resolve_name(sc.hazard_object) == asset_choice.resolve_name(task.target_asset)
    if hc is not None and hc.about_target and not sel.hazard_is_target:
        # built, the class's state would go on the target, not on the object the task is about
        raise ItemFailed(f"{hc.id} is about the target itself, but the task names {sc.hazard_object} at fault "
                         f"and {task.target_asset} as the target: it would be built as the {task.target_asset}'s hazard")
    # what goes inside the parent needs room there (only a real model is turned down for lacking it)
    holder = asset_choice.resolve_name(parent_raw) if relation == "inside" and parent_raw else None
    # a target that is also the named container must have room for the hazard: it keeps its draw
    stores_hazard = bool(sc.container) and not sel.hazard_is_target and \
        asset_choice.resolve_name(sc.container) == asset_choice.resolve_name(task.target_asset)
    least_of_hazard = asset_choice.size_bounds(kb, asset_choice.resolve_name(sc.hazard_object))[0]
    least_hazard = least_of_hazard if holder or stores_hazard else None
    room_for = least_hazard if holder else None
    # Big things first: they bound what fits in/on them.
    target = sel.target = sel.choose(
        task.target_asset, ObjectRole.HAZARD if sel.hazard_is_target else ObjectRole.TARGET, rank=True,
        room_for=room_for if asset_choice.resolve_name(task.target_asset) == holder else None,
        stores=least_hazard if stores_hazard else None,
        cap=_repair_cap(sel, task.target_asset, None) if sel.hazard_is_target else None,
    )
    parent = sel.parent = sel.choose(parent_raw, ObjectRole.AUXILIARY, room_for=room_for) if parent_raw else None
    cap = None
    if relation == "inside" and parent is not None:
        if not parent.asset.cavities:
            raise ItemFailed(f"placement {sel.placement} but {parent.catalogue} has no interior")
        cap = asset_choice.cavity_cap(parent.asset)
    hazard = sel.choose(sc.hazard_object, ObjectRole.HAZARD, cap=_repair_cap(sel, sc.hazard_object, cap))
    if hazard is target:
        target.role = ObjectRole.HAZARD

    container = None
    container_name = sc.container or (
        _first_known(hc.default_containers) if "$container" in variables else None
    )
    if container_name:
        container = sel.choose(container_name, ObjectRole.CONTAINER)
        if container is not hazard and container.asset.cavities:
            # The hazard must be able to go in: a 0.5 m plastic bag does not fit a 0.3 m bucket.
            # Draw the container again (other sizes), then a smaller hazard, before giving up.
            # A container that is also the scene's target keeps its draw (other steps refer to it).
            for _ in range(CONTAINER_REDRAWS if container is not target else 0):
                if hazard.size <= container_room(container.asset):
                    break
                sel.forget(container)
                container = sel.choose(container_name, ObjectRole.CONTAINER)
            # Another kind only when the task left the container open: a named bucket stays a bucket.
            if hazard.size > container_room(container.asset) and container is not target and not sc.container:
                container = _roomier_kind(sel, hc, container, container_name, hazard.size)
            room = container_room(container.asset)
            if hazard.size > room and hazard is not target:
                sel.forget(hazard)
                try:
                    hazard = sel.choose(sc.hazard_object, ObjectRole.HAZARD, cap=min(cap or room, room))
                except ItemFailed as exc:
                    # no smaller hazard fits either: draw the container at the size whose room holds the
                    # smallest hazard (the generator checked the roomiest; random redraws rarely land
                    # there). Scenes the redraws or a smaller hazard built stay exactly as they were.
                    if container is not target:
                        sel.forget(container)
                        container = sel.choose(container_name, ObjectRole.CONTAINER, stores=least_of_hazard)
                        room = container_room(container.asset)
                    if least_of_hazard > room:
                        others = [c for c in hc.default_containers if c != container_name]
                        raise ItemFailed(f"{exc}: the task names the {container_name}"
                                         + (f" (the class's other containers: {', '.join(others)})" if others else "")) from exc
                    hazard = sel.choose(sc.hazard_object, ObjectRole.HAZARD, cap=min(cap or room, room))
            if hazard.size > room:
                raise ItemFailed(f"{hazard.catalogue} ({hazard.size:.2f} m) does not fit {container.catalogue} "
                                 f"(room for {room:.2f} m)")
    sel.hazard, sel.container = hazard, container
    if "$support" in variables:
        sname = _first_known(hc.default_supports)
        if sname:
            sel.support_var = sel.choose(sname, ObjectRole.SUPPORT)

    extra = list(sc.co_objects) + [a.name for a in task.auxiliary_items if a.relevant]
    for raw in extra:
        if len(sel.aux) >= MAX_AUX:
            break
        try:
            cat = asset_choice.resolve_name(raw)
        except ItemFailed:
            continue  # an unknown co-object is decoration, not the hazard: leave it out
        if cat in sel.by_catalogue:
            continue
        sel.aux.append(sel.choose(cat, ObjectRole.AUXILIARY))
    bind_hazard(sel)
    return sel


def bind_hazard(sel: Selection) -> None:
    """Which object plays $hazard. Classes with both $target and $hazard (a closed window and a hot
    source) whose scenario names the target as its hazard object: the co-object with the class's
    properties."""
    sel.hazard_var = sel.hazard
    hc, target = sel.hc, sel.target
    if hc is not None and sel.hazard is target and {"$hazard", "$target"} <= sel.variables:
        sel.hazard_var = _co_object_for(hc, sel.kb, sel.aux)
        if sel.hazard_var is None:
            raise ItemFailed(f"no co-object can play $hazard for a {hc.id} scene")
        sel.hazard_var.role = ObjectRole.HAZARD
        target.role = ObjectRole.TARGET


def _open_as_the_fix_would(chosen: asset_choice.Chosen, label: str, hc) -> None:
    """A part the fix opens only part way (a window opened a crack for air) is built that way in a
    hazard-free scene: wide open it would be another class's hazard."""
    step = next((st for st in hc.recipe if st.action == "open_joint" and st.args.get("fraction")), None)
    if step is None:
        return
    fraction = float(step.args["fraction"])
    for joint in asset_choice.joints_with_label(chosen.asset, label):
        closed = joint.closed_value
        chosen.joint_values[joint.name] = float(closed + fraction * (asset_choice.far_end(joint) - closed))


def _roomier_kind(sel: Selection, hc, container, name: str, size: float):
    """Another of the class's usual containers that the hazard fits, or the container as it was. Only
    for a task that named no container (the class's first default did not fit)."""
    for alt in hc.default_containers:
        if alt == name:
            continue
        for _ in range(CONTAINER_REDRAWS):
            try:
                cand = sel.choose(alt, ObjectRole.CONTAINER)
            except ItemFailed:
                break
            if cand.asset.cavities and size <= container_room(cand.asset):
                sel.forget(container)
                return cand
            sel.forget(cand)
    return container


def set_initial_joints(sel: Selection) -> None:
    """Initial joint states: the task's articulations and the class template (and an interior the
    hazard sits in is opened unless the task says it is closed)."""
    task, hc, parent = sel.task, sel.hc, sel.parent
    uses: dict[str, list[tuple[str, str]]] = {}
    for a in task.articulations:
        try:
            uses.setdefault(asset_choice.resolve_name(a.object), []).append((a.part, a.initial_state))
        except ItemFailed:
            continue
    class_part = None  # the part whose state is the class's hazard (a window left shut, a door left open)
    if hc is not None and hc.articulation is not None:
        var_obj = {"$target": sel.target, "$hazard": sel.hazard}.get(hc.articulation.variable)
        if var_obj is not None:
            class_part = (var_obj.catalogue, hc.articulation.part)
            uses.setdefault(var_obj.catalogue, []).append(
                (hc.articulation.part, hc.articulation.initial_state)
            )
    if sel.placement.relation == "inside" and parent is not None:
        cav = asset_choice.biggest_cavity(parent.asset)
        if cav.joint is not None and not any(
            part_labels.encloses(p) and s == "closed" for p, s in uses.get(parent.catalogue, [])
        ):
            label = parent.asset.joint(cav.joint).label
            uses.setdefault(parent.catalogue, []).append((label, "open"))
    if sel.hazard_free:  # the class's part in its opposite state; any other part open or on is shut
        uses = {cat: [(p, (OPPOSITE_STATE if (cat, p) == class_part else SAFE_STATE).get(st, st)) for p, st in pairs]
                for cat, pairs in uses.items()}
    for cat, pairs in uses.items():
        if cat in sel.by_catalogue:
            asset_choice.set_articulations(sel.by_catalogue[cat], pairs, sel.rng)
    if sel.hazard_free and class_part is not None and class_part[0] in sel.by_catalogue:
        _open_as_the_fix_would(sel.by_catalogue[class_part[0]], class_part[1], hc)
    if not sel.hazard_free:
        _check_articulations(task, hc, sel.by_catalogue, sel.target)
    set_initial_states(sel)


def bind_roles(sel: Selection, support: Placed | None) -> dict[str, str]:
    """The role variables ($hazard, $target, $container, $support) bound to instance names."""
    relation, parent = sel.placement.relation, sel.parent
    bindings = {"$hazard": sel.hazard_var.name, "$target": sel.target.name}
    if sel.container is not None:
        bindings["$container"] = sel.container.name
    if sel.support_var is not None:
        bindings["$support"] = sel.support_var.name
    elif support is not None:
        bindings["$support"] = support.name
    elif relation == "on" and parent is not None:
        bindings["$support"] = parent.name
    if relation == "inside" and parent is not None and sel.container is None:
        bindings["$container"] = parent.name
    return bindings


def _co_object_for(hc, kb, candidates) -> asset_choice.Chosen | None:
    """The first candidate whose KB properties satisfy every has_property precondition on $hazard."""
    calls = [c for c in hc.preconditions if c.name == "has_property" and c.args.get("object") == "$hazard"]
    for ch in candidates:
        info = kb.objects.get(ch.catalogue)
        props = set(info.properties) if info is not None else set()
        ok = True
        for c in calls:
            has = bool(props & {p.strip() for p in str(c.args.get("property", "")).split("|")})
            ok &= has != c.negate
        if ok:
            return ch
    return None


def _first_known(names: list[str]) -> str | None:
    for n in names:
        try:
            return asset_choice.resolve_name(n)
        except ItemFailed:
            continue
    return None


def _check_articulations(task, hc, by_catalogue, target) -> None:
    """The joint the hazard class is about must exist on its object (else the hazard cannot be real)."""
    if hc is None or hc.articulation is None:
        return
    ch = target if hc.articulation.variable == "$target" else None
    if ch is None:
        return
    part = hc.articulation.part
    if not asset_choice.joints_with_label(ch.asset, part):
        raise ItemFailed(f"{ch.catalogue} has no '{part}' joint for a {hc.id} scene")
