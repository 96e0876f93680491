"""The builder's part of the judgement mix (``mix.py`` chooses what; this places and checks it).

Near-misses go well inside a table top, a second hazard on the floor with its bin; a hazard-free
scene puts the task's object where it is no hazard and, once settled, checks that it really is none.
"""

from __future__ import annotations

from anomalygen.errors import ItemFailed
from anomalygen.knowledge import load_kb
from anomalygen.knowledge.predicates import ROOM_FIXTURES
from anomalygen.scene import mix, select
from anomalygen.scene.instances import (
    HAZARD_NEAR_SIDE,
    INWARD,
    cavity_world,
    instance_name,
    placed_instance,
    surface_of,
)
from anomalygen.scene.layout import Layout, Placed
from anomalygen.scene.selection import Selection
from anomalygen.schema import ENCLOSING_LABELS, ObjectRole, ValidationCheck, ValidationReport


def place_judgement_items(sel: Selection, lay: Layout, placed: dict[str, Placed], surfaces: list[Placed],
                          items: mix.JudgementItems) -> None:
    """Near-misses well inside a table top (any that find no room are left out); the second hazard
    on the floor, with its bin when the scene has none."""
    rng = items.rng
    for cat in items.near_misses if surfaces else []:
        asset = select.pick_asset(cat, role=ObjectRole.CLUTTER, kb=sel.kb, task=sel.task, hc=None, rng=rng,
                                  real=sel.real_assets)
        p = placed_instance(select.Chosen(instance_name(cat, sel.used), cat, ObjectRole.CLUTTER, asset))
        holder = surfaces[int(rng.integers(len(surfaces)))]
        try:
            lay.place_on_surface(p, holder, surface_of(holder), inward=INWARD)
        except ItemFailed:
            continue
        placed[p.name] = p
    for cat, role, face in ((items.second_hazard, ObjectRole.HAZARD, False), (items.bin, ObjectRole.CONTAINER, True)):
        if cat is None:
            continue
        asset = select.pick_asset(cat, role=role, kb=sel.kb, task=sel.task, hc=None, rng=rng, real=sel.real_assets)
        p = placed_instance(select.Chosen(instance_name(cat, sel.used), cat, role, asset))
        lay.place_on_floor(p, relevant=True, face=face)
        placed[p.name] = p


def room_fixtures(kb, lay: Layout) -> list[Placed]:
    """Placed furniture and appliances: what the knowledge base counts as lining the room (a floor
    object beside one is out of the walkway)."""
    return [p for p in lay.items if p.fixed and set(ROOM_FIXTURES) & set(kb.properties_of(p.catalogue))]


def place_hazard_safely(sel: Selection, lay: Layout, placed: dict[str, Placed], support: Placed | None) -> None:
    """The task's object where it is no hazard: shut inside its container, else well inside the
    surface, else on the floor beside a piece of furniture, out of the walkway."""
    hazard, container = sel.hazard, sel.container
    hp = placed[hazard.name] = placed_instance(hazard)
    if container is not None and container is not hazard and container.asset.cavities:
        holder = placed.get(container.name)
        if holder is None:
            holder = placed[container.name] = placed_instance(container)
            lay.place_on_floor(holder, relevant=True, face=True)
        lo, hi, _ = cavity_world(holder)
        lay.place_in_cavity(hp, holder, (lo, hi))
        for joint in container.asset.joints:  # shut every lid, door and drawer of the container
            if select.kb_label(joint.label) in ENCLOSING_LABELS:
                holder.joint_values[joint.name] = float(joint.closed_value)
        holder.sweep = 0.0
        return
    if support is not None:
        lay.place_on_surface(hp, support, surface_of(support), inward=INWARD, near_side=HAZARD_NEAR_SIDE)
        return
    lay.place_beside(hp, room_fixtures(sel.kb, lay))


def check_hazard_free(report: ValidationReport, graph, hazard_class: str) -> ValidationReport:
    """A hazard-free variant must not show the task's hazard anywhere once settled."""
    from anomalygen.scene.truth import class_matches

    still = sorted(obj for cls, obj, _ in class_matches(graph, load_kb()) if cls == hazard_class)
    check = ValidationCheck(name="hazard_free", passed=not still,
                            detail=f"{hazard_class} still holds for {', '.join(still)}" if still else "made safe")
    report.checks.append(check)
    if still:
        report.ok, report.reason = False, check.detail
    return report
