"""The skill registry: every plan action has its skill, lookups name what exists, families claim
their sub-tasks, and a key is registered once."""

from __future__ import annotations

import ast
from types import SimpleNamespace

import pytest

from anomalygen.schema import SceneSpec, SubTask
from anomalygen.skills import catalogue
from anomalygen.skills.episode import LearningSettings
from anomalygen.skills.registry import ANY, Skill, UnknownSkill, lookup, register, registered, skill_for

PRIMITIVE_ACTIONS = {"approach", "close_joint", "close_lid", "grasp", "move_to", "open_joint", "open_lid", "pick",
                     "place_inside", "place_on", "pull", "push", "push_to", "release", "switch_off", "take_out_of"}


def test_the_catalogue_registers_every_scripted_and_learned_skill():
    assert catalogue.SKILL_MODULES  # importing the catalogue loaded them
    assert {a for _, a in registered("primitive")} == PRIMITIVE_ACTIONS
    assert registered("sac") == [("sac", ANY), ("sac", "switch_off")]
    grasp = lookup("primitive", "grasp")
    assert (grasp.method, grasp.action, grasp.key()) == ("primitive", "grasp", "primitive:grasp")
    assert lookup("primitive", "pick").key() == "primitive:pick"  # one class, one entry per action
    assert lookup("sac", "close_joint").key() == "sac:*"  # SAC learns any action from its reward
    assert lookup("sac", "switch_off").__name__ == "SwitchOffSkill"


def test_an_unknown_action_is_refused_with_the_registered_ones():
    with pytest.raises(UnknownSkill) as err:
        lookup("primitive", "juggle")
    msg = str(err.value)
    assert "'juggle'" in msg and all(a in msg for a in PRIMITIVE_ACTIONS)
    with pytest.raises(UnknownSkill, match="registered cem actions: none"):
        lookup("cem", "walk")


def test_a_key_is_registered_once():
    with pytest.raises(ValueError, match="primitive:grasp is registered twice"):
        register("primitive", "grasp")(type("AnotherGrasp", (Skill,), {}))


def test_every_action_a_planner_writes_has_a_skill():
    """The LLM planner's menu and the primitives the knowledge planner writes are registered actions."""
    from pathlib import Path

    import anomalygen.plan.planner as planner
    from anomalygen.plan.llm_prompt import PRIMITIVES

    tree = ast.parse(Path(planner.__file__).read_text())
    written = {kw.value.value for n in ast.walk(tree) if isinstance(n, ast.Call) for kw in n.keywords
               if kw.arg == "primitive" and isinstance(kw.value, ast.Constant)}
    assert written and written <= PRIMITIVE_ACTIONS, written - PRIMITIVE_ACTIONS
    assert set(PRIMITIVES) <= PRIMITIVE_ACTIONS, set(PRIMITIVES) - PRIMITIVE_ACTIONS


def _sac_step(**params) -> SubTask:
    return SubTask(id="s1", description="switch it off", method="sac", primitive="push", params=params)


def test_the_switch_off_family_claims_its_sub_tasks_when_rewards_are_specs():
    """A planned switch-off goes to the family skill (warm start); with reward code it is learned from
    scratch by the generic SAC skill; a primitive sub-task goes by its primitive."""
    spec = SceneSpec(scene_id="s", task_id="t", room="kitchen", seed=0, objects=[])
    episode = SimpleNamespace(spec=spec, learning=LearningSettings(reward_mode="spec"))
    st = _sac_step(family="switch_off", joint="kettle_0/switch")
    assert skill_for(episode, st).key() == "sac:switch_off"
    assert skill_for(episode, _sac_step(joint="cabinet_0/door_hinge")).key() == "sac:*"
    episode.learning = LearningSettings(reward_mode="code")
    assert skill_for(episode, st).key() == "sac:*"
    prim = SubTask(**{**st.model_dump(), "method": "primitive"})
    assert skill_for(episode, prim).key() == "primitive:push"
