"""The hidden ground truth of one scene, assembled for the judge (never shown to a detector).

The truth is the task's hazard class plus the object at fault. The object comes from the built
scene's ``$hazard`` binding (its instance name and its category); when the hazard *is* the target
asset (an open fridge), or no ``$hazard`` is bound, the ``$target`` binding counts too. Without a
``scene.json`` the proposal's catalogue names stand in, so hand-built graphs can be judged as well.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from anomalygen.schema import SceneGraph, SceneSpec, TaskProposal


def norm_name(name: str) -> str:
    """Case- and part-insensitive object name: 'Refrigerator_0:door' -> 'refrigerator_0'."""
    return name.strip().split(":", 1)[0].strip().lower().replace(" ", "_")


@dataclass(frozen=True)
class GroundTruth:
    task_id: str
    hazard_class: str
    category: str
    instances: frozenset[str]  # normalised instance names that count as the object at fault
    categories: frozenset[str]  # normalised categories of those instances
    text: str  # name + description + solution: what a free-text hypothesis is compared with
    label: str = field(default="")  # human-readable 'class on object' for reasons

    def names_object(self, target: str, graph: SceneGraph | None = None) -> bool:
        """Does a hypothesis' target (instance or category) denote the object at fault?

        An instance name is compared as an instance (another knife in the clutter is not the
        hazard); anything else is compared as a category.
        """
        t = norm_name(target)
        if t in self.instances:
            return True
        if graph is not None and any(norm_name(o.name) == t for o in graph.objects):
            return False
        return t in self.categories


def task_text(task: TaskProposal) -> str:
    parts = [task.name, task.description, task.solution]
    return ". ".join(p.strip().rstrip(".") for p in parts if p and p.strip())


def ground_truth(
    task: TaskProposal, spec: SceneSpec | None, graph: SceneGraph | None, *, hazard_variable: str | None = None
) -> GroundTruth:
    """``hazard_variable`` is the knowledge-base class's variable for the object at fault (``$target``
    for an open fridge); its binding counts as well as ``$hazard``'s."""
    instances: set[str] = set()
    categories: set[str] = set()
    by_name = {norm_name(o.name): o for o in graph.objects} if graph is not None else {}
    spec_cat = {norm_name(o.name): o.asset.category for o in spec.objects} if spec is not None else {}
    bindings = spec.bindings if spec is not None else {}
    chosen = [bindings["$hazard"]] if "$hazard" in bindings else []
    if "$target" in bindings and (not chosen or norm_name(bindings["$target"]) == norm_name(chosen[0])):
        chosen.append(bindings["$target"])
    if hazard_variable and hazard_variable in bindings:
        chosen.append(bindings[hazard_variable])
    for inst in chosen:
        key = norm_name(inst)
        instances.add(key)
        if key in by_name:
            categories.add(norm_name(by_name[key].category))
        if key in spec_cat:
            categories.add(norm_name(spec_cat[key]))
    if not instances:  # no built scene: the proposal's catalogue names
        categories.add(norm_name(task.scenario.hazard_object))
        if hazard_variable == "$target" or norm_name(task.scenario.hazard_object) == norm_name(task.target_asset):
            categories.add(norm_name(task.target_asset))
    shown = sorted(instances) or sorted(categories)
    return GroundTruth(
        task_id=task.id,
        hazard_class=task.hazard_class,
        category=str(task.category),
        instances=frozenset(instances),
        categories=frozenset(categories),
        text=task_text(task),
        label=f"{task.hazard_class} on {'/'.join(shown)}",
    )
