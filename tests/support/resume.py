"""Resume against the settings: a stage redoes its items when a setting they read changes, and only then.

Each per-item stage declares what its items read in one function, ``reads(settings)`` next to its
``run_stage`` (the config part of every item's fingerprint, ``runner.config_section``). The helpers
here turn that declaration into the keys it names (``stage_reads``) and test params over every key
of the settings (``cases``), give any key a valid other value (``changed``), make a small run folder
that every per-item stage can run on (``small_run``), and swap each stage's item function for a
double that writes the stage's outputs without building, detecting, planning or simulating anything
(``double_items``): what is under test is the runner's skip/redo decision with the stage's real
``run_stage`` and its real choice of settings, key by key (``assert_resume``).

    from support.resume import assert_resume, cases

    @pytest.mark.parametrize(("base", "key", "redo"), cases("plan", {"knowledge": {}}))
    def test_x(request, base, key, redo):
        assert_resume("plan", request, base, key, redo=redo)
"""

from __future__ import annotations

import importlib
import shutil
import types
from collections.abc import Iterator
from enum import Enum
from pathlib import Path
from typing import Any, Literal, Union, get_args, get_origin

import pytest
from pydantic import BaseModel, SecretStr

from anomalygen.config import Settings
from anomalygen.runfolder import RunFolder, write_jsonl, write_model
from anomalygen.schema import (
    Detection,
    Engine,
    HazardCategory,
    Plan,
    Provenance,
    Scenario,
    SceneGraph,
    SceneSpec,
    SkillResult,
    SuccessSpec,
    TaskProposal,
    ValidationReport,
    Verdict,
)

TASKS = ("t-a", "t-b")
RAN: list[str] = []  # the items the doubles ran (inline, in this process), in order
# how items are run, never what they make: "ray" would start Ray for a batch with nothing to do
HOW_TO_RUN = ("executor",)
# a configured backend either way: "none" fails a stage that needs an LLM, and "llamacpp" loads a model
SPECIAL = {"llm.backend": lambda v: "anthropic" if v != "anthropic" else "openai"}
# an LLM for the bases that need one; nothing is ever sent to it (the items are doubles)
LLM = {"backend": "openai", "model": "m", "base_url": "http://127.0.0.1:9/v1", "cache": False}


def settings(**over: Any) -> Settings:
    """Test settings: quiet, one worker (doubles run inline), and ``over`` on top."""
    return Settings(**{"quiet": True, "workers": 1, **over})


# --------------------------------------------------------------------------- keys


def all_keys(node: BaseModel, prefix: str = "") -> Iterator[str]:
    """Every leaf key of the settings, dotted (``detect.noise.enabled``, ``seed``)."""
    for name in type(node).model_fields:
        value = getattr(node, name)
        if isinstance(value, BaseModel):
            yield from all_keys(value, f"{prefix}{name}.")
        else:
            yield f"{prefix}{name}"


def stage_reads(stage: str, base: Settings) -> list[str]:
    """The keys the stage's ``reads(settings)`` declares under ``base``: those whose change changes
    what it returns, because their value is in it (``plan.max_fixes``) or because they decide what is
    (``llm.vision`` decides whether the build puts the LLM's identity in)."""
    reads = _module(stage).reads
    declared = reads(base)
    return [key for key in all_keys(base) if key not in HOW_TO_RUN and reads(changed(base, key)) != declared]


def cases(stage: str, bases: dict[str, dict]) -> list:
    """pytest params (base settings, key, whether the stage must redo) for every key of the settings,
    under each named base: the keys the stage's ``reads`` declares are redone, every other one skipped."""
    out = []
    for name, over in bases.items():
        base = settings(**over)
        read = stage_reads(stage, base)
        for key in all_keys(base):
            if key in HOW_TO_RUN:
                continue
            redo = key in read
            out.append(pytest.param(base, key, redo, id=f"{name}-{key}-{'redo' if redo else 'skip'}"))
    return out


def other_value(key: str, annotation: Any, current: Any) -> Any:
    """A valid value other than ``current`` for a key of this type."""
    if key in SPECIAL:
        return SPECIAL[key](current)
    kinds = [annotation]
    if get_origin(annotation) in (Union, types.UnionType):
        kinds = [a for a in get_args(annotation) if a is not type(None)]
    kind = kinds[0]
    if kind is bool:
        return not current
    if get_origin(kind) is Literal:
        return next(o for o in get_args(kind) if o != current)
    if isinstance(kind, type) and issubclass(kind, Enum):
        return next(m for m in kind if m != current)
    if kind is int:
        return (current or 0) + 1
    if kind is float:
        return current / 2 if current else 0.5
    if kind in (str, SecretStr):
        return "changed"
    if get_origin(kind) is list:
        return [*current, "close_joint"]
    raise TypeError(f"no other value for {key} ({annotation}): teach support/resume.py::other_value")


def changed(base: Settings, key: str) -> Settings:
    """A copy of ``base`` with ``key`` set to another valid value."""
    out = base.model_copy(deep=True)
    *path, leaf = key.split(".")
    node = out
    for part in path:
        node = getattr(node, part)
    before = getattr(node, leaf)
    setattr(node, leaf, other_value(key, type(node).model_fields[leaf].annotation, before))
    assert getattr(node, leaf) != before, key
    return out


# --------------------------------------------------------------------------- a run folder


def task(tid: str) -> TaskProposal:
    return TaskProposal(id=tid, name="n", explanation="e", description="d", category=HazardCategory.HOUSEHOLD_HAZARD,
                        hazard_class="store_sharp_objects", target_asset="knife",
                        scenario=Scenario(hazard_object="knife", room="kitchen", placement="counter_edge"),
                        provenance=Provenance(engine=Engine.KNOWLEDGE, mode="plain"))


def small_run(root: Path) -> RunFolder:
    """Two tasks with every per-item stage's inputs in place: a built scene (its spec, graph, MJCF and
    truth), a detection, a plan and one learn result each."""
    run = RunFolder.create(root)
    write_jsonl(run.tasks_path, [task(t) for t in TASKS])
    for tid in TASKS:
        scene = run.scene_dir(tid)
        write_model(scene / "scene.json", _scene(tid, 0))
        write_model(scene / "scene_graph.json", SceneGraph(scene_id=tid, room="kitchen", objects=[]))
        (scene / "scene.xml").write_text("<mujoco/>\n")
        (scene / "truth.json").write_text("{}\n")
        write_model(run.plan_path(tid), _plan(tid, "detected", Engine.KNOWLEDGE))
        write_model(run.skill_dir(tid, 0) / "result.json", SkillResult(task_id=tid, seed=0, success=True))
    write_jsonl(run.detections_path, [Detection(task_id=t, scene_id=t, detector="rules", hypotheses=[]) for t in TASKS])
    return run


def _scene(tid: str, seed: int) -> SceneSpec:
    return SceneSpec(scene_id=tid, task_id=tid, room="kitchen", seed=seed, objects=[],
                     validation=ValidationReport(ok=True))


def _plan(tid: str, source: str, engine: Engine) -> Plan:
    return Plan(task_id=tid, source=source, engine=engine, subtasks=[], success=SuccessSpec(predicates=[]))


# --------------------------------------------------------------------------- item doubles


def fake_build(task_id: str, payload: str, ctx) -> str:
    RAN.append(task_id)
    write_model(ctx.run.scene_dir(task_id) / "scene.json", _scene(task_id, ctx.settings.seed))
    return task_id


def fake_detect(task_id: str, payload: dict, ctx) -> dict:
    from anomalygen.detect.stage import detection_path

    RAN.append(task_id)
    write_model(detection_path(ctx.run, task_id),
                Detection(task_id=task_id, scene_id=task_id, detector=ctx.settings.detect.detector, hypotheses=[]))
    return {"claims": 0, "error": None, "fallback": None, "usage": None}


def fake_plan(task_id: str, payload: dict, ctx) -> str:
    RAN.append(task_id)
    settings = ctx.settings
    write_model(ctx.run.plan_path(task_id), _plan(task_id, settings.plan.source, settings.engine_for("plan")))
    return str(ctx.run.plan_path(task_id))


def fake_learn(item_id: str, payload: dict, ctx) -> dict:
    RAN.append(item_id)
    task_id, seed = item_id.rsplit("@seed", 1)
    write_model(ctx.run.skill_dir(task_id, int(seed)) / "result.json",
                SkillResult(task_id=task_id, seed=int(seed), success=True))
    return {"success": True}


def fake_judge(task_id: str, payload: dict, ctx) -> dict:
    from anomalygen.referee.stage import _seeds, verdict_path

    RAN.append(task_id)
    out = {}
    for seed in _seeds(ctx.run, task_id):
        write_model(verdict_path(ctx.run, task_id, seed),
                    Verdict(task_id=task_id, seed=seed, status="unresolved", resolved=False))
        out[seed] = "unresolved"
    return {"verdicts": out}


# stage -> (its module, the item function run_stage hands to run_items, the double)
STAGES = {
    "build": ("anomalygen.scene.stage", "build_item", fake_build),
    "detect": ("anomalygen.detect.stage", "_item", fake_detect),
    "plan": ("anomalygen.plan.stage", "plan_item", fake_plan),
    "learn": ("anomalygen.learn.stage", "learn_item", fake_learn),
    "judge": ("anomalygen.referee.stage", "judge_item", fake_judge),
}


def _module(stage: str):
    return importlib.import_module(STAGES[stage][0])


def double_items(stage: str, monkeypatch) -> None:
    """Swap the stage's item function for its double (and, for detect, the LLM client for a stub that
    is never asked: the llm detectors are only constructed). Writes skip ``fsync``: what is under test
    is which items run, not that a file survives a power cut (the cases run in half the time)."""
    import os

    _, fn, fake = STAGES[stage]
    module = _module(stage)
    monkeypatch.setattr(module, fn, fake)
    monkeypatch.setattr(os, "fsync", lambda fd: None)
    if stage == "detect":
        monkeypatch.setattr(module, "_client", lambda llm: object())


_PREPARED: dict[tuple[str, str], tuple[Path, set[str]]] = {}  # (stage, base) -> a run done under base


def _prepared(stage: str, request, base: Settings) -> tuple[Path, set[str]]:
    """A run folder with every item of the stage done under ``base`` (made once per session)."""
    key = (stage, base.model_dump_json())
    if key not in _PREPARED:
        run = small_run(request.getfixturevalue("tmp_path_factory").mktemp(f"resume-{stage}") / "run")
        items = _ran(stage, run, base)
        assert len(items) == len(TASKS), items
        assert not _ran(stage, run, base)  # nothing changed: nothing redone
        _PREPARED[key] = run.root, items
    return _PREPARED[key]


def _ran(stage: str, run: RunFolder, settings: Settings) -> set[str]:
    """The items the stage runs under ``settings`` (its others are skipped)."""
    RAN.clear()
    summary = _module(stage).run_stage(run, settings)
    assert summary.failed == 0, summary.errors
    assert summary.done == len(RAN), "items ran outside this process, unseen by the doubles"
    return set(RAN)


def assert_resume(stage: str, request, base: Settings, key: str, *, redo: bool) -> None:
    """On a run whose items were all done under ``base``, run the stage with ``key`` changed: every item
    is redone (``redo``) or none is. ``request``: the test's pytest request (for its temp folders)."""
    double_items(stage, request.getfixturevalue("monkeypatch"))
    prepared, items = _prepared(stage, request, base)
    run = RunFolder(shutil.copytree(prepared, request.getfixturevalue("tmp_path") / "run"))
    redone = items & _ran(stage, run, changed(base, key))
    if redo:
        assert redone == items, f"{key} is read by {stage} items, yet {sorted(items - redone)} were skipped"
    else:
        assert not redone, f"no {stage} item reads {key}, yet {sorted(redone)} were redone"
