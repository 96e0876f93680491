"""The scripted skills of the registry, one class per group of plan actions (``("primitive", action)``).

Each reads the sub-task's params (object, region, part, ...; role variables resolved through the
episode's plan bindings) and calls the motion primitives of this package. They need no learned
policy: the scene says where to go.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from anomalygen.schema import DOOR, LID, LID_LABELS, SubTask, part_labels
from anomalygen.skills import geometry
from anomalygen.skills.registry import Skill, SkillOutcome, register
from anomalygen.skills.scripted import access, primitives, push, relocate, transfer
from anomalygen.skills.scripted.joints import closed_parts, drive_joints

if TYPE_CHECKING:  # pragma: no cover
    from anomalygen.skills.episode import Episode

PRIMITIVE = "primitive"
GRASP_LIFT = 0.12  # m a grasped object is lifted unless the step says (``lift``)


def _object(episode: Episode, subtask: SubTask) -> str:
    """The object the step acts on: its ``object`` param, else the plan's ``$hazard``."""
    return _resolve(episode, subtask.params.get("object")) or episode.bindings.get("$hazard", "")


def _resolve(episode: Episode, value) -> str | None:
    """A param naming an object: a role variable (``$fuel``) through the plan's bindings, else as written."""
    if value is None:
        return None
    value = str(value)
    return episode.bindings.get(value, value) if value.startswith("$") else value


@register(PRIMITIVE, "grasp", "pick")
class Grasp(Skill):
    """Suction-grasp the object from above (or by its side) and lift it."""

    def run(self, episode: Episode, subtask: SubTask) -> SkillOutcome:
        lift = float(subtask.params.get("lift", GRASP_LIFT))
        return primitives.grasp(episode, _object(episode, subtask), lift=lift)


@register(PRIMITIVE, "approach")
class Approach(Skill):
    """Base near the object, cup just above its top."""

    def run(self, episode: Episode, subtask: SubTask) -> SkillOutcome:
        return primitives.approach(episode, _object(episode, subtask))


@register(PRIMITIVE, "release")
class Release(Skill):
    """Let go of whatever the cup holds."""

    def run(self, episode: Episode, subtask: SubTask) -> SkillOutcome:
        return primitives.release(episode)


@register(PRIMITIVE, "move_to", "place_inside", "place_on")
class Place(Skill):
    """Carry the object (grasping it first if it is not held) into a container or onto a support."""

    def run(self, episode: Episode, subtask: SubTask) -> SkillOutcome:
        prm, obj = subtask.params, _object(episode, subtask)
        region = str(prm.get("region") or prm.get("container") or prm.get("support") or "")
        if region == "surface_centre":  # back from the edges (move_away_from_edge): its own top, if it has room
            support = geometry.surface_centre_of(episode, obj)  # None on the floor: the nearest safe top
            return relocate.back_from_edge(episode, obj, support, release_after=bool(prm.get("release", True)))
        if episode.driver.held != obj:  # move_to without a preceding grasp: pick first
            g = primitives.grasp(episode, obj)
            if not g.success:
                return g
        into = any(c.name == "inside" and not c.negate for c in subtask.success.predicates) \
            or subtask.primitive == "place_inside"
        res = primitives.move_to(episode, obj, region, release_after=bool(prm.get("release", True)), into=into)
        opened = episode.memory.opened
        shut = [lab for lab in closed_parts(episode, region) if lab != DOOR or not opened.get(region)]
        if shut and into and not opened.get(region):  # say why an 'inside' will fail
            res.detail += f"; {region}'s {', '.join(shut)} closed and the plan did not open it"
        return res


@register(PRIMITIVE, "push_to")
class PushTo(Skill):
    """Slide a free object over the floor beside a piece of furniture."""

    def run(self, episode: Episode, subtask: SubTask) -> SkillOutcome:
        prm = subtask.params
        return push.push_to(episode, _object(episode, subtask), str(prm.get("region") or prm.get("support") or ""))


@register(PRIMITIVE, "take_out_of")
class TakeOut(Skill):
    """Lift the object out of a container or appliance; it stays held."""

    def run(self, episode: Episode, subtask: SubTask) -> SkillOutcome:
        prm = subtask.params
        return transfer.take_out_of(episode, _object(episode, subtask),
                                    str(prm.get("region") or prm.get("container") or ""))


@register(PRIMITIVE, "close_lid", "open_lid")
class Lid(Skill):
    """Every lid or flap of a portable container, shut or opened."""

    def run(self, episode: Episode, subtask: SubTask) -> SkillOutcome:
        prm = dict(subtask.params)
        prm.setdefault("part", part_labels.any_of(LID_LABELS))
        motion = "push" if subtask.primitive == "close_lid" else "pull"
        return drive_joints(episode, subtask, _object(episode, subtask), motion, prm)


@register(PRIMITIVE, "push", "pull")
class PushPull(Skill):
    """Push a part shut or pull it open; with ``access``, open a container to put something in (or
    take it out) and shut what was opened again."""

    def run(self, episode: Episode, subtask: SubTask) -> SkillOutcome:
        prm, obj = dict(subtask.params), _object(episode, subtask)
        if prm.get("access"):
            if subtask.primitive == "pull":
                return access.open_for_access(episode, obj, part_labels.alternatives(str(prm.get("part", LID))), prm.get("contents"))
            return access.close_opened(episode, obj, every=bool(prm.get("contents")))
        return drive_joints(episode, subtask, obj, subtask.primitive or "", prm)


@register(PRIMITIVE, "close_joint", "open_joint", "switch_off")
class DriveJoint(Skill):
    """Drive the object's parts with the step's label to closed (off) or open."""

    def run(self, episode: Episode, subtask: SubTask) -> SkillOutcome:
        return drive_joints(episode, subtask, _object(episode, subtask), subtask.primitive or "", dict(subtask.params))


@register(PRIMITIVE, "move_away")
class MoveAway(Skill):
    """Carry the object onto a safe support at least ``distance`` m from the ``from`` object."""

    def run(self, episode: Episode, subtask: SubTask) -> SkillOutcome:
        prm = subtask.params
        frm = _resolve(episode, prm.get("from"))
        if not frm or prm.get("distance") is None:
            return SkillOutcome(False, 0, "move_away needs 'from' (an object) and 'distance' (metres)")
        return relocate.move_away(episode, _object(episode, subtask), frm, float(prm["distance"]))


@register(PRIMITIVE, "take_off")
class TakeOff(Skill):
    """Lift the object off what it lies on onto ``support`` (else the nearest safe support)."""

    def run(self, episode: Episode, subtask: SubTask) -> SkillOutcome:
        support = _resolve(episode, subtask.params.get("support") or subtask.params.get("region"))
        return relocate.take_off(episode, _object(episode, subtask), support or None)


@register(PRIMITIVE, "rotate_inward")
class RotateInward(Skill):
    """Turn a pan so that its handle points back over the hob or counter it stands on."""

    def run(self, episode: Episode, subtask: SubTask) -> SkillOutcome:
        return relocate.rotate_inward(episode, _object(episode, subtask))
