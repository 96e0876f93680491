"""The four classes of the push_to / close_lid / take_out_of / place_on actions, end to end.

A fixed task file (each class with several hazard objects and rooms) goes through the real CLI:
``brainstorm --tasks`` (validated copy), ``build`` (single-hazard scenes: no near-misses, second
hazards or hazard-free variants, so each scene holds the one hazard of its task), ``detect
--detector rules``, then ``plan`` and ``learn`` with the oracle (``plan.source = ground_truth``:
the builder's class and bindings) and, with ``--detected``, from perception as well. Prints the
loop table per class, judged against each scene's truth.json by the referee, then one JSON line.

    .venv/bin/python benchmarks/bench_new_classes.py [--seeds 3] [--workers 2] [--detected] [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from anomalygen import procs

#: (hazard class, target asset, hazard object, placement, room) per task
TASKS = [
    ("push_heavy_item_out_of_walkway", "Table", "dumbbell", "walkway", "living_room"),
    ("push_heavy_item_out_of_walkway", "StorageFurniture", "dumbbell", "walkway", "hallway"),
    ("push_heavy_item_out_of_walkway", "Table", "hammer", "walkway", "office"),
    ("close_open_portable_container", "Box", "Box", "floor", "bedroom"),
    ("close_open_portable_container", "Box", "Box", "floor", "nursery"),
    ("close_open_portable_container", "Suitcase", "Suitcase", "floor", "hallway"),
    ("remove_item_from_appliance", "Microwave", "fork", "inside:Microwave", "kitchen"),
    ("remove_item_from_appliance", "Microwave", "spoon", "inside:Microwave", "kitchen"),
    ("remove_item_from_appliance", "Microwave", "fork", "inside:Microwave", "kitchen"),
    ("pick_item_off_floor_onto_desk", "Table", "Phone", "floor", "office"),
    ("pick_item_off_floor_onto_desk", "Table", "Eyeglasses", "walkway", "bedroom"),
    ("pick_item_off_floor_onto_desk", "Table", "mug", "floor", "living_room"),
    ("pick_item_off_floor_onto_desk", "Table", "glass", "walkway", "kitchen"),
]


def task_lines() -> list[str]:
    from anomalygen.knowledge import load_kb
    from anomalygen.schema import TaskProposal

    kb = load_kb()
    out = []
    for i, (hc, target, hazard, placement, room) in enumerate(TASKS, start=1):
        t = TaskProposal(id=f"t{i:04d}-{hc.replace('_', '-')}", name=f"{hazard} ({hc})", explanation="benchmark task",
                         description=f"A {hazard} ({placement}) in the {room}.", category=kb.hazard_classes[hc].category,
                         hazard_class=hc, target_asset=target,
                         scenario=dict(hazard_object=hazard, room=room, placement=placement, co_objects=[]),
                         provenance=dict(engine="knowledge", mode="plain"))
        out.append(t.model_dump_json())
    return out


def _cli(*args: str, env=None) -> None:
    exe = Path(sys.executable).with_name("anomalygen")
    subprocess.run([str(exe), *args, "--quiet"], check=True, env=env, preexec_fn=procs.end_with_parent)


def main() -> int:
    from anomalygen.evaluate.hazard_table import hazard_table, markdown
    from anomalygen.runfolder import RunFolder

    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=3, help="executions per scene")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--detected", action="store_true", help="also plan and learn from the rule detector's output")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    root = Path(a.out or tempfile.mkdtemp(prefix="bench_new_classes_"))
    root.mkdir(parents=True, exist_ok=True)
    tasks_file = root / "tasks_in.jsonl"
    tasks_file.write_text("\n".join(task_lines()) + "\n")
    env = {**os.environ, "ANOMALYGEN_LEARN__VIDEO": "false", "ANOMALYGEN_BUILD__NEAR_MISSES": "0",
           "ANOMALYGEN_BUILD__MULTI_HAZARD": "0", "ANOMALYGEN_BUILD__HAZARD_FREE": "0"}
    t0 = time.perf_counter()
    out: dict = {"name": "new_classes", "tasks": len(TASKS), "seeds": a.seeds}
    for mode in ("ground_truth", "detected") if a.detected else ("ground_truth",):
        run = root / mode
        menv = {**env, "ANOMALYGEN_PLAN__SOURCE": mode}
        _cli("brainstorm", "--run", str(run), "--tasks", str(tasks_file), env=menv)
        _cli("build", "--run", str(run), "--workers", str(a.workers), env=menv)
        _cli("detect", "--run", str(run), "--detector", "rules", env=menv)
        _cli("plan", "--run", str(run), env=menv)
        _cli("learn", "--run", str(run), "--seeds", str(a.seeds), "--workers", str(a.workers), env=menv)
        rf = RunFolder(run)
        table = hazard_table(rf, [t.id for t in rf.load_tasks()], a.seeds)
        print(markdown(table, f"plan.source = {mode}"))
        tot = table.total
        out[mode] = {"hazards": tot.hazards, "detected": tot.detected, "planned": tot.planned, "runs": tot.runs,
                     "resolved": tot.resolved, "runs_with_new_hazards": table.runs_with_new_hazards,
                     "runs_acting_on_safe": table.runs_acting_on_safe,
                     "by_class": {k: v.model_dump() for k, v in table.by_class.items()}}
    out["wall_s"] = round(time.perf_counter() - t0, 1)
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
