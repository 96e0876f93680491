"""Validation of a settled scene: physics first, then the hazard itself.

The paper's VLM check let 4 of 111 scenes with overlapping assets through. Here a scene is valid only
if MuJoCo says so: no contact penetrates more than 1 mm, every loose object has come to rest, nothing
fell out of the room, and the hazard class's detection preconditions from the knowledge base hold on
the scene graph of the settled state (so the hazard is real, not just intended).
"""

from __future__ import annotations

import numpy as np

from anomalygen.schema import SceneSpec, ValidationCheck, ValidationReport

MAX_PENETRATION = 0.001  # m
MAX_LIN_VEL = 0.05  # m/s (a marble may still creep; the KB predicates are what matter)
MAX_ANG_VEL = 0.5  # rad/s
INITIAL_OVERLAP = 0.004  # m: deeper than this before settling means the layout overlaps


def _owners(model, spec: SceneSpec) -> np.ndarray:
    """Geom -> object index (robot = -2, room = -1)."""
    from anomalygen.robot.agent import Agent
    from anomalygen.world.graph import geom_owners

    owner = geom_owners(model, spec)
    owner[Agent.geom_ids(model)] = -2
    return owner


def _contacts(model, data):
    n = data.ncon
    return (
        np.asarray(data.contact.geom1[:n]),
        np.asarray(data.contact.geom2[:n]),
        np.asarray(data.contact.dist[:n]),
    )


def initial_overlap(model, data, spec: SceneSpec) -> str | None:
    """A reason when two different things interpenetrate before any physics ran, else None."""
    owner = _owners(model, spec)
    g1, g2, dist = _contacts(model, data)
    for a, b, d in zip(g1, g2, dist, strict=True):
        if d < -INITIAL_OVERLAP and owner[a] != owner[b]:
            return f"initial overlap of {_who(model, spec, owner, a)} and {_who(model, spec, owner, b)} ({-d * 1000:.0f} mm)"
    return None


def _who(model, spec, owner, geom) -> str:
    o = owner[geom]
    if o >= 0:
        return spec.objects[o].name
    return "the robot" if o == -2 else "the room"


def max_loose_speed(model, data, placed) -> float:
    """Largest linear speed of any loose (free-jointed) object."""
    best = 0.0
    for p in placed.values():
        if p.fixed:
            continue
        v = data.joint(f"{p.name}/free").qvel
        best = max(best, float(np.linalg.norm(v[:3])), 0.1 * float(np.linalg.norm(v[3:])))
    return best


def validate(model, data, spec: SceneSpec, graph, hc) -> ValidationReport:
    """Physics and hazard checks of the current (settled) state."""
    owner = _owners(model, spec)
    checks: list[ValidationCheck] = []
    g1, g2, dist = _contacts(model, data)
    pen, worst, self_pen, self_worst = 0.0, "", 0.0, ""
    for a, b, d in zip(g1, g2, dist, strict=True):
        if owner[a] == owner[b] and owner[a] >= 0:
            # parts of one articulated asset touching each other: the asset's own business
            if -d > self_pen:
                self_pen, self_worst = float(-d), _who(model, spec, owner, a)
        elif -d > pen:
            pen, worst = float(-d), f"{_who(model, spec, owner, a)} / {_who(model, spec, owner, b)}"
    checks.append(
        ValidationCheck(
            name="max_penetration",
            passed=pen <= MAX_PENETRATION,
            value=pen,
            limit=MAX_PENETRATION,
            detail=worst,
        )
    )
    checks.append(
        ValidationCheck(
            name="self_contact_penetration",
            passed=True,
            value=self_pen,
            detail=f"informational: {self_worst}" if self_worst else "informational",
        )
    )

    lin, ang = 0.0, 0.0
    for o in spec.objects:
        if o.fixed:
            continue
        v = data.joint(f"{o.name}/free").qvel
        lin, ang = max(lin, float(np.linalg.norm(v[:3]))), max(ang, float(np.linalg.norm(v[3:])))
    checks.append(
        ValidationCheck(
            name="settled_linear_velocity", passed=lin <= MAX_LIN_VEL, value=lin, limit=MAX_LIN_VEL
        )
    )
    checks.append(
        ValidationCheck(
            name="settled_angular_velocity", passed=ang <= MAX_ANG_VEL, value=ang, limit=MAX_ANG_VEL
        )
    )

    lost = [g.name for g in graph.objects if g.position[2] < -0.02 or not np.all(np.isfinite(g.position))]
    checks.append(ValidationCheck(name="objects_in_room", passed=not lost, detail=", ".join(lost)))

    if hc is not None:
        from anomalygen.knowledge.predicates import PredicateError, evaluate

        for call in hc.preconditions:
            try:
                res = evaluate(call, graph, spec.bindings)
                passed, detail = res.holds, res.explanation
            except PredicateError as exc:
                passed, detail = False, str(exc)
            name = ("not " if call.negate else "") + call.name
            checks.append(ValidationCheck(name=f"precondition:{name}", passed=passed, detail=detail))
    else:
        checks.append(
            ValidationCheck(
                name="precondition:none",
                passed=True,
                detail="hazard class 'other': no machine-checkable preconditions",
            )
        )

    failed = [c for c in checks if not c.passed]
    reason = ""
    if failed:
        c = failed[0]
        reason = (
            f"{c.name} failed"
            + (f": {c.detail}" if c.detail else "")
            + (f" ({c.value:.4g} > {c.limit:.4g})" if c.value is not None and c.limit is not None else "")
        )
    return ValidationReport(ok=not failed, checks=checks, reason=reason)


#: Edge placements ("at the edge of the counter") hold within this distance of the edge (m): the
#: near_edge predicate's own default, so a line's edge is the mechanisms' edge.
STATED_EDGE = 0.1


def stated_checks(task, spec: SceneSpec, graph) -> list[ValidationCheck]:
    """What a user's line said, checked in the settled scene: the object at fault is where the line put
    it (in, on, near another object; on a support kind; at its edge), and every state the line gave an
    object shows (a sink full of water, a burner lit). A line is built as stated or not at all."""
    from anomalygen.scene.asset_choice import resolve_name

    checks: list[ValidationCheck] = []
    hazard = spec.bindings.get("$hazard")
    by_category: dict[str, list[str]] = {}
    for o in spec.objects:
        by_category.setdefault(o.asset.category, []).append(o.name)
    bound = set(spec.bindings.values())

    def instance(catalogue: str) -> str | None:
        names = by_category.get(resolve_name(catalogue), [])
        return next((n for n in names if n in bound), names[0] if names else None)

    rel = {(r.subject, r.predicate, r.object) for r in graph.relations}
    p = task.scenario.placement
    if hazard is not None and p.other is not None:
        other = instance(p.other)
        ok = other is not None and (
            (hazard, p.relation, other) in rel
            or (p.relation == "near" and ((other, "near", hazard) in rel))
            or (p.relation == "on" and (hazard, "inside", other) in rel)  # on a stove's burner is in its top
        )
        checks.append(ValidationCheck(name=f"stated:{p.relation} {p.other}", passed=ok,
                                      detail=f"{hazard} {p.relation} {other}" if ok else
                                      f"the line puts {hazard} {p.relation} {p.other}, the scene does not"))
    elif hazard is not None and p.relation == "at_edge":
        d = graph.get(hazard).distance_to_edge
        ok = d is not None and d <= STATED_EDGE
        checks.append(ValidationCheck(name="stated:at the edge", passed=ok, value=d, limit=STATED_EDGE,
                                      detail=f"{hazard} is {'not on a raised surface' if d is None else f'{d:.2f} m from the edge'}"))
    for name, states in task.scenario.states.items():
        inst = instance(name)
        shown = set(graph.get(inst).states) if inst is not None else set()
        for state in states:
            ok = state in shown
            checks.append(ValidationCheck(name=f"stated:{name} {state}", passed=ok,
                                          detail=f"{inst} shows {', '.join(sorted(shown)) or 'no state'}"))
    return checks


def with_stated_checks(report: ValidationReport, task, spec: SceneSpec, graph) -> ValidationReport:
    """``report`` with ``stated_checks`` added; the first that fails fails the build, naming what the
    scene could not show."""
    checks = stated_checks(task, spec, graph)
    failed = next((c for c in checks if not c.passed), None)
    return ValidationReport(ok=failed is None, checks=report.checks + checks,
                            reason=f"{failed.name} failed: {failed.detail}" if failed else report.reason)
