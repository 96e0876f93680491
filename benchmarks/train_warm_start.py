"""Train the switch-off family's warm start over built scenes and measure it on held-out scenes.

The learn stage loads ``anomalygen/data/policies/switch_off.zip`` for every switch-off sub-task
(``skills/learned/part_subtask.py``) and fine-tunes it only where it does not already succeed. This script makes
that file: it collects, for each built scene of the class ``switch_off_appliance`` in the training
run folder, one start per knob or switch that is on (the cup holding the part after
``part_motion.grasp_part``), trains one SAC policy on all of them at once (``PartTurnEnv`` picks a
start per episode; ``--n-envs`` vectorised envs), evaluates during training on the held-out run
folder's scenes, and finally measures the saved policy on every held-out start over ``--eval-seeds``
seeded episodes (different start noise). Scenes come from the real pipeline (knowledge brainstorm
and build, single-hazard); make them with ``--make`` (brainstorm 300 tasks with seed 0 for training,
seed 1 for held-out, build the switch-off ones).

    .venv/bin/python benchmarks/train_warm_start.py --make --train /tmp/ws/train --held-out /tmp/ws/test \\
        [--steps 6000] [--n-envs 4] [--seed 0] [--demos 0] [--out src/anomalygen/data/policies/switch_off.zip]

Prints one JSON line: steps, wall time, training curve, held-out success per start and overall.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from anomalygen import procs

CLASS = "switch_off_appliance"
DEFAULT_OUT = Path(__file__).resolve().parents[1] / "src" / "anomalygen" / "data" / "policies" / "switch_off.zip"


def make_run(run: Path, seed: int, n: int = 300) -> None:
    """Brainstorm ``n`` knowledge tasks and build the switch-off ones (single-hazard scenes)."""
    exe = Path(sys.executable).with_name("anomalygen")
    env = {**os.environ, "ANOMALYGEN_BUILD__HAZARD_FREE": "0", "ANOMALYGEN_BUILD__MULTI_HAZARD": "0",
           "ANOMALYGEN_BUILD__NEAR_MISSES": "0"}
    subprocess.run([str(exe), "brainstorm", "--run", str(run), "--engine", "knowledge", "--n", str(n),
                    "--seed", str(seed), "--quiet"], check=True, env=env, preexec_fn=procs.end_with_parent)
    tasks = [json.loads(line) for line in (run / "tasks.jsonl").read_text().splitlines() if line.strip()]
    only = [x for t in tasks if t["hazard_class"] == CLASS for x in ("--only", t["id"])]
    subprocess.run([str(exe), "build", "--run", str(run), "--workers", "1", "--seed", str(seed), *only, "--quiet"],
                   check=True, env=env, preexec_fn=procs.end_with_parent)


def starts_of(run: Path, log=lambda m: print(m, file=sys.stderr)) -> list:
    """One PartStart per knob/switch that is on, in every switch-off scene of the run folder."""
    import mujoco
    import numpy as np

    from anomalygen.plan.planner import plan_from_kb
    from anomalygen.runfolder import read_model
    from anomalygen.schema import SceneSpec
    from anomalygen.skills.episode import Episode
    from anomalygen.skills.learned.part_env import PartStart
    from anomalygen.skills.learned.part_subtask import far_value
    from anomalygen.skills.part_motion import grasp_part
    from anomalygen.world.graph import load_scene
    from anomalygen.world.perception import perceived_spec

    tasks = {json.loads(x)["id"]: json.loads(x) for x in (run / "tasks.jsonl").read_text().splitlines() if x.strip()}
    out = []
    for tid in sorted(tasks):
        sd = run / "scenes" / tid
        if tasks[tid]["hazard_class"] != CLASS or not (sd / "scene.json").is_file():
            continue
        # the builder's bindings name the appliance (this is the oracle training set-up, not the robot)
        bindings = read_model(sd / "scene.json", SceneSpec).bindings
        for st in plan_from_kb(tid, CLASS, bindings, spec=read_model(sd / "scene.json", SceneSpec)).subtasks:
            model, data, spec = load_scene(sd)
            spec = perceived_spec(spec)
            ep = Episode(model, data, spec, rng=np.random.default_rng(0))
            joint = str(st.params.get("joint"))
            js = next(j for o in spec.objects for j in o.joint_states if j.name == joint)
            ok, why = grasp_part(ep, joint)
            if not ok:
                log(f"{tid} {joint}: {why}")
                continue
            kind = mujoco.mjtState.mjSTATE_INTEGRATION
            snap = np.empty(mujoco.mj_stateSize(model, kind))
            mujoco.mj_getState(model, data, snap, kind)
            out.append((tid, PartStart(model, snap, spec, st, dict(bindings), joint, float(js.closed_value), far_value(js))))
    return out


def demonstrations(starts, episodes: int, seed: int) -> dict:
    """Transitions of the scripted reference (``part_motion.reference_action``) on the training starts."""
    import numpy as np

    from anomalygen.skills.learned.part_env import make_part_env
    from anomalygen.skills.part_motion import reference_action

    env = make_part_env(starts)
    cols = {k: [] for k in ("obs", "next_obs", "action", "reward", "done")}
    wins = 0
    for k in range(episodes):
        obs, _ = env.reset(seed=seed + k)
        done = False
        while not done:
            a = reference_action(obs)
            nxt, r, term, trunc, info = env.step(a)
            for key, v in zip(cols, (obs, nxt, a, r, term), strict=True):
                cols[key].append(v)
            obs, done = nxt, term or trunc
        wins += bool(info.get("is_success"))
    env.close()
    out = {k: np.asarray(v, dtype=np.float32 if k != "done" else np.float32) for k, v in cols.items()}
    out["success"] = wins / max(1, episodes)
    return out


def seeded_with(demos: dict, bc_steps: int, seed: int):
    """A ``train_sac`` pretrain hook: behaviour cloning on the demos, and the demos in the replay buffer."""
    from anomalygen.skills.learned.sac import behaviour_clone

    def pretrain(model) -> None:
        nll = behaviour_clone(model, demos["obs"], demos["action"], steps=bc_steps, seed=seed)
        print(f"behaviour cloning: {len(demos['obs'])} transitions, final NLL {nll:.2f}", file=sys.stderr)
        n = model.n_envs
        for i in range(0, len(demos["obs"]) - n + 1, n):
            sl = slice(i, i + n)
            model.replay_buffer.add(demos["obs"][sl], demos["next_obs"][sl], demos["action"][sl],
                                    demos["reward"][sl], demos["done"][sl], [{} for _ in range(n)])

    return pretrain


def held_out_success(policy, starts, seeds: int) -> list[dict]:
    from anomalygen.skills.learned.part_env import make_part_env
    from anomalygen.skills.learned.sac import evaluate_policy

    rows = []
    for tid, s in starts:
        env = make_part_env([s])
        rate, ret = evaluate_policy(policy, env, seeds, seed=50_000)
        env.close()
        rows.append({"task": tid, "joint": s.joint, "success": rate, "return": round(ret, 2)})
    return rows


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--train", required=True, help="run folder with the training scenes")
    ap.add_argument("--held-out", required=True, help="run folder with the held-out scenes")
    ap.add_argument("--make", action="store_true", help="brainstorm and build both run folders first")
    ap.add_argument("--steps", type=int, default=6000)
    ap.add_argument("--n-envs", type=int, default=4)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--eval-every", type=int, default=1000)
    ap.add_argument("--eval-seeds", type=int, default=3)
    ap.add_argument("--out", default=str(DEFAULT_OUT))
    ap.add_argument("--demos", type=int, default=0, help="episodes of the scripted reference to seed SAC with (0: none)")
    ap.add_argument("--bc-steps", type=int, default=2000)
    a = ap.parse_args()

    from anomalygen.skills.learned.part_env import make_part_env
    from anomalygen.skills.learned.sac import train_sac

    train_run, test_run = Path(a.train), Path(a.held_out)
    if a.make:
        make_run(train_run, 0)
        make_run(test_run, 1)
    t0 = time.perf_counter()
    train, test = starts_of(train_run), starts_of(test_run)
    t_collect = time.perf_counter() - t0
    print(f"{len(train)} training starts, {len(test)} held-out starts ({t_collect:.0f} s)", file=sys.stderr)
    starts = [s for _, s in train]
    demos, pretrain = None, None
    if a.demos > 0:
        demos = demonstrations(starts, a.demos, a.seed)
        pretrain = seeded_with(demos, a.bc_steps, a.seed)
        print(f"reference: success {demos['success']:.2f} on {a.demos} training episodes", file=sys.stderr)
    eval_env = make_part_env([s for _, s in test])
    policy, res = train_sac(lambda: make_part_env(starts), a.steps, seed=a.seed, eval_every=a.eval_every,
                            eval_episodes=max(5, len(test)), learning_starts=500, net_arch=(64, 64),
                            n_envs=a.n_envs, eval_env=eval_env, stop_at=None, pretrain=pretrain,
                            log=lambda m: print(m, file=sys.stderr, flush=True))
    out = Path(a.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    policy.save(str(out))
    rows = held_out_success(policy, test, a.eval_seeds)
    scenes = sorted({r["task"] for r in rows})
    per_scene = {t: all(r["success"] >= 0.5 for r in rows if r["task"] == t) for t in scenes}
    summary = {"demos": a.demos, "reference_success": None if demos is None else demos["success"],
               "steps": res.steps, "n_envs": a.n_envs, "train_starts": len(train), "held_out_starts": len(test),
               "held_out_scenes": len(scenes), "train_wall_s": round(res.wall_s, 1), "collect_s": round(t_collect, 1),
               "best_eval_success": res.best_success, "best_step": res.best_step,
               "held_out_start_success": round(sum(r["success"] for r in rows) / max(1, len(rows)), 3),
               "held_out_scene_success": round(sum(per_scene.values()) / max(1, len(scenes)), 3),
               "policy_bytes": out.stat().st_size, "curve": res.curve, "rows": rows}
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
