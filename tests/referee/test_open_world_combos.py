"""Issue 25's acceptance on built scenes: hazards composed from mechanisms, beyond the 26 hand-written
classes, each written as a user would write it, built, detected and resolved.

For each line: ``brainstorm --tasks-text``'s reader composes the task (the class asserted here), the
real builder builds it (offline engine, no clutter, no extra hazards), the referee's truth names the
composed class on the object the line is about, the offline rules find it on the perceived scene graph
(no answer key), the planner binds and plans the fix from that detection and the perceived scene,
the real skills carry it out in the real simulator (scripted primitives: a learned switch-off would
cost minutes per control), and ``anomalygen.referee.judge`` judges the settled end state.

Each test builds its own scene (about a second; a scene that cannot be built fails its test alone).

Left out, each for a real reason (see the issue): a power strip *in* a full sink (the detector ranked
``move_electrical_away_from_water`` first, and no safe support stands 0.6 m from the sink; the near-water
rule no longer fires on a thing inside the water, and the combo has not been tried again since), a ball or a
blanket in the crib (built since the crib is read as a container; the suction cup does not reliably
catch a thing lying down in it), a dumbbell taken down off a shelf (it rolls to the table's edge), a toy car near the crib
(no safe is placed in the nursery), a fork in the toaster (it does not fit the slot), a blanket on a
heater (its top is too small); paper towels on a hob and a hair dryer beside a bathtub pass or fail
with the scene their task id draws (no base pose by the counter; no safe support 0.6 m from the tub).
"""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from anomalygen.config import Settings
from anomalygen.schema import SkillMethod

pytestmark = pytest.mark.slow

QUIET_MIX = {"clutter": 0, "near_misses": 0, "multi_hazard": 0.0, "hazard_free": 0.0}

#: (line, the composed class, the category of the object at fault)
COMBOS = [
    ("A towel is lying on the lit stove burner in the kitchen.", "clear_burning_risk_off_heat_source", "towel"),
    ("An iron was left switched on on the bedroom floor.", "switch_off_tool_on_floor", "iron"),
    ("A towel lies right next to the lit stove in the kitchen.", "clear_burning_risk_near_heat_source", "towel"),
    ("The space heater is on right next to the curtains in the bedroom.", "switch_off_heater_near_fabric",
     "SpaceHeater"),
    ("A ball was left on the stairs in the hallway.", "clear_item_from_stairs", "ball"),
    ("A power strip lies right next to the full kitchen sink.", "move_electrical_away_from_water", "PowerStrip"),
    ("The baby gate at the stairs was left open in the hallway.", "close_baby_gate", "BabyGate"),
    ("A lit candle stands next to the curtains in the living room.", "move_candle_away_from_fabric", "candle"),
    ("A lit candle stands next to the paper towels in the kitchen.", "move_candle_away_from_fabric", "candle"),
    ("A hair dryer was left on on the bathroom counter.", "switch_off_heat_tool", "hair_dryer"),
    ("A cleaning spray stands next to the bread loaf on the kitchen counter.", "separate_chemical_from_food",
     "cleaning_spray"),
    ("The tap of the kitchen sink was left running.", "turn_off_running_tap", "Sink"),
    ("The bathtub tap was left running.", "turn_off_running_tap", "Bathtub"),
    ("A pot on the stove in the kitchen has its handle turned outward.", "turn_pan_handle_inward", "KitchenPot"),
    # with real models the safe in this scene is shallower than the spray is tall: it is laid on its side first
    ("A bottle of cleaning spray was put in the fridge.", "remove_chemical_from_fridge", "cleaning_spray"),
]


def _settings() -> Settings:
    return Settings(quiet=True, workers=1, build=QUIET_MIX)


#: Issue 23's leftover: classes that put a knife or a cleaner away for an adult's sake; their fix must
#: still shut it away from a toddler (a latching container, ``KnowledgeBase.containers_for``), or the
#: child's class fires on the stored object and the referee rejects the fix.
STORED = [
    ("store_sharp_objects", "kitchen_knife", "counter_edge", "storage_box"),
    ("manage_chemical_risks", "bleach_bottle", "counter_edge", "storage_box"),
]


@pytest.fixture(scope="module")
def tasks():
    """Every line's task (read as ``--tasks-text`` reads it) and every stored task, by key."""
    from tests.scene.conftest import make_task

    from anomalygen.brainstorm.free_text import tasks_from_lines
    from anomalygen.knowledge import load_kb

    out = {}
    for line, _, _ in (getattr(c, "values", c) for c in COMBOS):  # one file per line: a task's id (and so its scene) does not move with the list
        (out[line],), errors = tasks_from_lines([line], load_kb())
        assert errors == {}
    for cls, obj, placement, container in STORED:
        out[cls] = make_task(f"t-{cls}", cls, "Table", obj, placement, container=container)
    return out


@pytest.fixture(scope="module")
def scenes(tmp_path_factory):
    return tmp_path_factory.mktemp("open_world_combos")


def _built(tasks, scenes, key):
    """(task, scene folder) of one key, the scene built by the real builder."""
    from anomalygen.scene.build import build_scene

    task = tasks[key]
    scene_dir = scenes / task.id
    build_scene(task, seed=0, settings=_settings(), out_dir=scene_dir)
    return task, scene_dir


def _plan_from_detection(task_id, scene_dir, detection, settings):
    """The plan stage's own path from a detection and the perceived scene (``plan/stage.py``)."""
    from anomalygen.plan.stage import _plan_from_perception

    ctx = SimpleNamespace(settings=settings, run=SimpleNamespace(scene_dir=lambda _tid: scene_dir))
    plan = _plan_from_perception(task_id, {"detection": detection.model_dump(mode="json")}, ctx)
    scripted = [st.model_copy(update={"method": SkillMethod.PRIMITIVE}) for st in plan.subtasks]
    return plan.model_copy(update={"subtasks": scripted})


@pytest.mark.parametrize(("line", "hazard_class", "category"), COMBOS,
                         ids=[f"{v[1]}-{v[2]}-{i}" for i, c in enumerate(COMBOS) for v in [getattr(c, "values", c)]])
def test_built_detected_and_resolved(tasks, scenes, tmp_path, line, hazard_class, category):
    task, scene_dir = _built(tasks, scenes, line)
    assert task.hazard_class == hazard_class and task.source == "user_text"
    _built_detected_and_resolved(task, scene_dir, tmp_path, hazard_class, category)


@pytest.mark.parametrize(("hazard_class", "category", "placement", "container"), STORED, ids=[c[0] for c in STORED])
def test_a_stored_childs_hazard_goes_where_a_child_cannot_open(tasks, scenes, tmp_path, hazard_class, category,
                                                               placement, container):
    from anomalygen.runfolder import read_model
    from anomalygen.schema import SceneSpec

    task, scene_dir = _built(tasks, scenes, hazard_class)
    spec = read_model(scene_dir / "scene.json", SceneSpec)
    assert {o.asset.category for o in spec.objects} >= {container, "Safe"}  # the task's box, and a safe offered
    _built_detected_and_resolved(task, scene_dir, tmp_path, hazard_class, category, stored_in="Safe")


def _built_detected_and_resolved(task, scene_dir, tmp_path, hazard_class, category, stored_in=None):
    from anomalygen.detect.stage import detect_scene
    from anomalygen.learn.execute import execute_plan
    from anomalygen.referee import judge, load_manifest
    from anomalygen.world.graph import load_scene, scene_graph
    from anomalygen.world.perception import load_scene_graph
    from anomalygen.world.state import restore_state

    # the referee's truth: the composed class on the object the line is about
    truth = load_manifest(scene_dir)
    (intended,) = [h for h in truth.hazards if h.source == "intended"]
    graph = load_scene_graph(scene_dir)
    assert intended.hazard_class == hazard_class and graph.get(intended.object).category == category
    # detection from perception alone finds it
    settings = _settings()
    det = detect_scene(task.id, graph, settings)
    assert (hazard_class, intended.object) in {(h.hazard_class, h.target_object) for h in det.hypotheses}
    # the planner's fix, carried out by the real skills in the simulator
    plan = _plan_from_detection(task.id, scene_dir, det, settings)
    assert any(st.params.get("object") == intended.object for st in plan.subtasks)
    state = tmp_path / "final_state.npz"
    res = execute_plan(scene_dir, plan, seed=0, retries=settings.learn.retries, final_state_path=state,
                       recheck_fixes=settings.plan.max_fixes)
    # the referee's verdict on the settled end state (the robot's own verdict is not asked)
    model, data, spec = load_scene(scene_dir)
    restore_state(state, model, data)
    verdict = judge(scene_dir, model, data)
    details = [(s.id, s.success, s.detail) for s in res.subtasks]
    assert verdict.status == "resolved" and verdict.resolved, (verdict, details)
    assert [h.object for h in verdict.hazards if h.resolved] == [h.object for h in truth.hazards]
    if stored_in is not None:
        inside = {r.object for r in scene_graph(model, data, spec).relations
                  if r.subject == intended.object and r.predicate == "inside"}
        assert {graph.get(c).category for c in inside if c} == {stored_in}
