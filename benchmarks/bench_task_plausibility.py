"""Issue 39's generator figures: plausible homes and scenario-level diversity of the offline engine.

For each seed, drafts ``--n`` tasks with the knowledge engine and reports:
- ``misplaced``: objects standing in a room the household table does not give them (every fixture and
  piece of furniture a task names: the object at fault, its support, the placement's other object,
  the container and the co-objects), with examples;
- ``distinct``: distinct (class, object at fault, placement, room) scenarios;
- ``top_room_share``: the largest share of tasks in one room;
- ``unusual``: portable objects a task names (the object at fault, the placement's other object, the
  co-objects) outside the rooms ``objects.json`` keeps them in (a toaster in a bathroom);
- ``classes``: distinct hazard classes drawn.

Run: ``.venv/bin/python benchmarks/bench_task_plausibility.py --seeds 0-9 --n 111 [--big 1000]``.
Building (``--build``: the share of tasks the scene builder makes) is measured by
``bench_task_builds.py``.
"""

from __future__ import annotations

import argparse
import collections
import json


def _seeds(text: str) -> list[int]:
    if "-" in text:
        a, b = text.split("-")
        return list(range(int(a), int(b) + 1))
    return [int(s) for s in text.split(",")]


def measure(seed: int, n: int) -> dict:
    from anomalygen.brainstorm.knowledge_engine import KnowledgeEngine
    from anomalygen.knowledge import load_kb
    from anomalygen.knowledge.households import load_households, misplaced_objects

    kb, homes = load_kb(), load_households()
    unusual = 0

    tasks = KnowledgeEngine(seed=seed).run(n)
    keys = collections.Counter()
    rooms = collections.Counter()
    bad = []
    for t in tasks:
        s = t.scenario
        keys[(t.hazard_class, s.hazard_object, s.placement, s.room)] += 1
        rooms[s.room] += 1
        for name in misplaced_objects(t):
            bad.append(f"{t.id}: {name} in {s.room}")
        for name in [s.hazard_object, s.placement.other, *s.co_objects]:
            if name and name not in homes.fixtures and name in kb.objects and kb.objects[name].rooms:
                unusual += s.room not in kb.objects[name].rooms
    room, top = rooms.most_common(1)[0]
    return {
        "seed": seed,
        "n": len(tasks),
        "distinct": len(keys),
        "top_room": room,
        "top_room_share": round(top / len(tasks), 3),
        "misplaced": len(bad),
        "unusual": unusual,
        "classes": len({t.hazard_class for t in tasks}),
        "examples": bad[:5],
    }


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="0")
    ap.add_argument("--n", type=int, default=111)
    ap.add_argument("--big", type=int, default=0, help="also draw this many tasks at seed 0")
    args = ap.parse_args()
    rows = [measure(s, args.n) for s in _seeds(args.seeds)]
    for r in rows:
        print(json.dumps(r))
    if args.big:
        print(json.dumps({"big": measure(0, args.big)}))
    print(json.dumps({"total_misplaced": sum(r["misplaced"] for r in rows), "min_distinct": min(r["distinct"] for r in rows),
                      "max_top_room_share": max(r["top_room_share"] for r in rows)}))


if __name__ == "__main__":
    main()
