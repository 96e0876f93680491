"""Driving an object's parts by label: close (or open) every door, lid or knob the step is about.

The planner names an object's first joint, but a fridge has a freezer and a main door and either may
be the open one; the scene state says which to push, so the joints are re-chosen here from the
sub-task's label (its ``part`` param, else the label its success predicate names).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from anomalygen.schema import ENCLOSING_LABELS, SubTask, part_labels
from anomalygen.skills.registry import SkillOutcome
from anomalygen.skills.scripted.parts import actuate_part

if TYPE_CHECKING:  # pragma: no cover
    from anomalygen.skills.episode import Episode

ACCESS_LABELS = ENCLOSING_LABELS  # parts that open a way into a container
NEARLY_CLOSED_TOL = 0.1  # open fraction under which a part still blocks the way in
OPEN_FRACTION = 0.6  # how far an opened part goes unless the recipe says (a window for air: a crack)


def label_of(st: SubTask, prm: dict) -> str | None:
    """The part label the step is about: its ``part`` param, else the label its success predicate names."""
    if prm.get("part"):
        return str(prm["part"])
    for call in st.success.predicates:
        if "label" in call.args:
            return str(call.args["label"])
    return None


def drive_joints(ep: Episode, st: SubTask, obj: str, prim: str, prm: dict) -> SkillOutcome:
    """Close (or open) every part of ``obj`` with the step's label, most open first."""
    drv = ep.driver
    label = label_of(st, prm)
    opening = prim in ("pull", "open_joint")
    cands = []
    for o in ep.spec.objects:
        if o.name != obj:
            continue
        for js in o.joint_states:
            if label is not None and js.label not in part_labels.alternatives(label) and js.name != prm.get("joint"):
                continue
            lo, hi = js.range
            closed = js.closed_value
            far = hi if abs(hi - closed) > abs(lo - closed) else lo
            goal = far if opening else closed
            gap = abs(float(drv.data.joint(js.name).qpos[0]) - goal) / max(abs(hi - lo), 1e-6)
            fraction = float(prm.get("open_fraction", OPEN_FRACTION))
            cands.append((gap, js.name, closed + fraction * (far - closed) if opening else goal, closed,
                          0.025 * abs(hi - lo)))
    if not cands and prm.get("joint") is not None:
        cands = [(1.0, str(prm["joint"]), float(prm.get("target", 0.0)), 0.0, 0.02)]
    if not cands:
        return SkillOutcome(False, 0, f"{obj} has no articulated part labelled {label!r} to {prim}")
    cands.sort(key=lambda c: -c[0])
    steps, details = 0, {}
    for _ in range(2):  # a second pass: closing one door can knock a neighbour open again
        for _, joint, goal, closed, tol in cands:
            if abs(float(drv.data.joint(joint).qpos[0]) - goal) <= tol:  # done already (pushed along by another)
                continue
            r = actuate_part(ep, joint, goal, closed=closed, tol=tol)
            steps += r.steps
            details[joint] = r.detail
    ok = all(abs(float(drv.data.joint(j).qpos[0]) - g) <= t for _, j, g, _, t in cands)
    return SkillOutcome(ok, steps, "; ".join(details.values()) or f"{label} parts of {obj} already there")


def closed_parts(ep: Episode, name: str) -> list[str]:
    """Labels of the object's lids, doors, flaps and drawers that are (nearly) closed right now."""
    out = []
    for o in ep.spec.objects:
        if o.name == name:
            for js in o.joint_states:
                if js.label in ACCESS_LABELS and js.is_closed(NEARLY_CLOSED_TOL, float(ep.data.joint(js.name).qpos[0])):
                    out.append(js.label)
    return sorted(set(out))
