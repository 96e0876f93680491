"""An Episode on a scene built from a task the benchmark loop drew, verbatim: the skill tests rerun
a real failure on the very scene it happened in."""

from __future__ import annotations

from pathlib import Path

#: bench_primitives.py's build settings: one hazard, no second hazard, near-miss or hazard-free draw
PRIMITIVES_BUILD = {"hazard_free": 0, "multi_hazard": 0, "near_misses": 0}


def episode_on_built_task(fixture: Path, out: Path, *, primitives: bool = False):
    """Build the task in ``fixture`` (a TaskProposal JSON) at seed 0 with the default settings, as the
    loop does (``primitives``: as the primitives benchmark does, the judgement mix off), into ``out``,
    and return an Episode on its perceived scene with an empty plan."""
    from anomalygen.config import Settings
    from anomalygen.rng import item_rng
    from anomalygen.scene.build import build_scene
    from anomalygen.schema import Plan, TaskProposal
    from anomalygen.skills.episode import Episode, EpisodeBudget, LearningSettings
    from anomalygen.world.perception import load_perceived_scene

    task = TaskProposal.model_validate_json(fixture.read_text())
    settings = Settings(build=PRIMITIVES_BUILD) if primitives else Settings()
    build_scene(task, seed=0, settings=settings, out_dir=out)
    model, data, perceived = load_perceived_scene(out)
    plan = Plan(task_id=task.id, source="detected", engine="knowledge", subtasks=[], success={"predicates": []})
    return Episode(model, data, perceived, seed=0, rng=item_rng(0, task.id), plan=plan, budget=EpisodeBudget(),
                   learning=LearningSettings())
