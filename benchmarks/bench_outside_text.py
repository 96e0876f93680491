"""Plain hazard lines written by others, through ``--tasks-text``: is the hazard built the one the line states?

The set (``benchmarks/data/outside_hazards.jsonl``, sources in its README) labels every line by hand
with the object at fault (a catalogue name, or a free word when the catalogue has no such thing),
the acceptable dangers (mechanism ids; empty when no mechanism covers the danger) and a fix. A line
whose object is not in the knowledge base or whose danger no mechanism covers should be refused.

For every line the offline reader (``brainstorm/free_text.py``) composes a hazard or refuses, and the
line counts as
- faithful: composed with a labelled object and a labelled danger, or refused when the label says it
  cannot be stated;
- silent substitution: composed, but with another object or danger than the label (or composed when
  it should have been refused);
- wrong refusal: refused although the label names a catalogue object and a mechanism.
Composed lines whose objects have no asset yet are counted as "needs assets" (they compose, but
cannot be built until the asset lands). Reported for the set, per half (dev / held_out: the parser
was developed on dev only) and per source.

``--build`` also runs the composed, buildable lines through the pipeline (build, detect with rules,
plan from perception, learn) and counts built, detected and resolved by the referee's verdict.

    .venv/bin/python benchmarks/bench_outside_text.py [--half dev|held_out|all] [--build --out DIR --workers N] [--json]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from collections import Counter, defaultdict
from pathlib import Path
from urllib.parse import urlparse

from anomalygen import procs

DATA = Path(__file__).parent / "data" / "outside_hazards.jsonl"


def load_set(half: str = "all") -> list[dict]:
    rows = [json.loads(line) for line in DATA.read_text(encoding="utf-8").splitlines() if line.strip()]
    return [r for r in rows if half == "all" or r["half"] == half]


def source_of(row: dict) -> str:
    """A source family for the per-source table: the benchmark's name or the web site."""
    src = row["source"]
    if src.startswith("IS-Bench"):
        return "IS-Bench"
    if src.startswith("anomalygen issue"):
        return "issue 25"
    return urlparse(src).netloc.removeprefix("www.") or src


def judge(row: dict, kb, tg) -> dict:
    """What the reader did with one line, and how that compares with the label."""
    from anomalygen.brainstorm.line_compose import Refused

    objects = [o for o in row["object"] if o in kb.objects]
    expect_refusal = not objects or not row["danger"]
    out = {"id": row["id"], "half": row["half"], "source": source_of(row), "line": row["line"]}
    try:
        _, comp = tg.compose(row["line"])
    except Refused as exc:
        out.update(outcome="refused", reason=str(exc), verdict="faithful" if expect_refusal else "wrong_refusal")
        return out
    mech = comp.hc.composition.mechanism
    ok = not expect_refusal and comp.fault.name in objects and mech in row["danger"]
    # the task the line becomes must put the state on that object too: a class about its target
    # (left on, left open) sets it on the task's target_asset
    task = tg.proposal(row["line"], 1)
    built_on = task.target_asset if comp.hc.about_target else task.scenario.hazard_object
    ok = ok and built_on == comp.fault.name
    out.update(outcome="composed", hazard_class=comp.hc.id, mechanism=mech, object=comp.fault.name,
               other=comp.other.name if comp.other else None, built_on=built_on,
               verdict="faithful" if ok else "substitution")
    missing = [n for n in (comp.fault.name, comp.other.name if comp.other else None) if n and n not in tg_catalogue()]
    out["needs_assets"] = missing
    return out


def tg_catalogue() -> set[str]:
    from anomalygen.brainstorm.drawable import catalogue

    return set(catalogue())


def table(results: list[dict]) -> dict:
    n = len(results)
    c = Counter(r["verdict"] for r in results)
    composed = [r for r in results if r["outcome"] == "composed"]
    return {
        "lines": n,
        "faithful": c["faithful"],
        "faithful_pct": round(100 * c["faithful"] / n, 1) if n else 0.0,
        "substitutions": c["substitution"],
        "substitution_pct": round(100 * c["substitution"] / n, 1) if n else 0.0,
        "wrong_refusals": c["wrong_refusal"],
        "refused": sum(r["outcome"] == "refused" for r in results),
        "composed": len(composed),
        "composed_needing_assets": sum(bool(r.get("needs_assets")) for r in composed),
    }


# --------------------------------------------------------------------------- the pipeline (--build)


def verdicts(run_dir: Path) -> dict[str, bool]:
    """The referee's verdict per task (resolved on any seed), from the judge stage's verdict files."""
    from anomalygen.referee import load_verdict
    from anomalygen.runfolder import RunFolder

    folder = RunFolder(run_dir)
    out: dict[str, bool] = {}
    for t in folder.load_tasks():
        seeds = sorted(int(p.name.removeprefix("seed")) for p in (folder.skills_dir / t.id).glob("seed*"))
        found = [v for v in (load_verdict(folder, t.id, k) for k in seeds) if v is not None]
        if found:
            out[t.id] = any(v.resolved for v in found)
    return out


def run_pipeline(lines: list[str], out: Path, workers: int = 1) -> dict:
    """brainstorm --tasks-text, build, detect (rules), plan and learn from perception, then the referee's
    judge stage; counts per stage."""
    from anomalygen.evaluate.run_metrics import load_detections, load_manifests
    from anomalygen.runfolder import RunFolder

    out.mkdir(parents=True, exist_ok=True)
    text = out / "lines.txt"
    text.write_text("\n".join(lines) + "\n", encoding="utf-8")
    exe = str(Path(sys.executable).with_name("anomalygen"))
    run = out / "run"
    par = ["--workers", str(workers)]
    steps = [["brainstorm", "--engine", "knowledge", "--out", str(run), "--tasks-text", str(text)],
             ["build", "--run", str(run), *par], ["detect", "--run", str(run), "--detector", "rules"],
             ["plan", "--run", str(run)], ["learn", "--run", str(run), *par], ["judge", "--run", str(run), *par]]
    for args in steps:
        subprocess.run([exe, *args, "--quiet"], check=False, preexec_fn=procs.end_with_parent)
    folder = RunFolder(run)
    tasks = folder.load_tasks()
    manifests = load_manifests(folder, tasks)
    dets = {d.task_id: d for d in load_detections(folder)}
    detected = 0
    for t in tasks:
        m, d = manifests.get(t.id), dets.get(t.id)
        if m is None or d is None or not m.hazards:
            continue
        intended = m.hazards[0]
        detected += any(h.target_object == intended.object and h.hazard_class in (None, intended.hazard_class)
                        for h in d.hypotheses[:3])
    resolved = verdicts(run)
    return {"tasks": len(tasks), "built": len(manifests), "detected": detected,
            "resolved": sum(resolved.values()), "judged": len(resolved)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--half", choices=["dev", "held_out", "all"], default="all")
    ap.add_argument("--build", action="store_true", help="also build, detect, plan and learn the composed lines")
    ap.add_argument("--out", type=Path, default=Path("runs/outside_text"))
    ap.add_argument("--workers", type=int, default=1, help="worker processes of each pipeline stage (--build)")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--lines", action="store_true", help="print every line's outcome")
    args = ap.parse_args()

    from anomalygen.brainstorm.free_text import TextGrounder
    from anomalygen.knowledge import load_kb

    kb = load_kb()
    tg = TextGrounder(kb, catalogue=set(kb.objects))  # compose against the knowledge; assets are counted apart
    rows = load_set(args.half)
    results = [judge(r, kb, tg) for r in rows]
    report = {"set": table(results), "halves": {}, "sources": {}}
    for half in ("dev", "held_out"):
        part = [r for r in results if r["half"] == half]
        if part:
            report["halves"][half] = table(part)
    by_source: dict[str, list[dict]] = defaultdict(list)
    for r in results:
        by_source[r["source"]].append(r)
    report["sources"] = {s: table(rs) for s, rs in sorted(by_source.items())}
    report["refusal_reasons"] = {r["id"]: r["reason"] for r in results if r["outcome"] == "refused"}
    report["substitutions"] = {r["id"]: f"{r['object']} / {r['mechanism']} ({r['hazard_class']})"
                               for r in results if r["verdict"] == "substitution"}
    if args.build:
        buildable = [r["line"] for r in results if r["verdict"] == "faithful" and r["outcome"] == "composed"
                     and not r.get("needs_assets")]
        report["pipeline"] = run_pipeline(buildable, args.out, args.workers)
    if args.lines:
        for r in results:
            what = r.get("reason") or f"{r['object']} / {r['mechanism']} / {r['hazard_class']}"
            print(f"{r['id']} {r['half']:8s} {r['verdict']:13s} {what[:90]} | {r['line']}")
    if args.json:
        print(json.dumps(report))
        return
    for name, t in [("all", report["set"]), *report["halves"].items()]:
        print(f"{name:9s} lines {t['lines']:3d}  faithful {t['faithful']:3d} ({t['faithful_pct']:5.1f} %)  "
              f"substitutions {t['substitutions']:2d} ({t['substitution_pct']:4.1f} %)  wrong refusals {t['wrong_refusals']:2d}  "
              f"refused {t['refused']:2d}  composed {t['composed']:2d} (needing assets {t['composed_needing_assets']})")
    print("per source:")
    for s, t in report["sources"].items():
        print(f"  {s:40s} {t['faithful']:2d}/{t['lines']:2d} faithful, {t['substitutions']} substituted, "
              f"{t['wrong_refusals']} wrongly refused")
    print("refused lines:")
    for rid, reason in report["refusal_reasons"].items():
        print(f"  {rid}: {reason}")
    if report["substitutions"]:
        print("substitutions:")
        for rid, what in report["substitutions"].items():
            print(f"  {rid}: {what}")
    if "pipeline" in report:
        print("pipeline:", json.dumps(report["pipeline"]))


if __name__ == "__main__":
    main()
