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
PARAPHRASES = Path(__file__).parent / "data" / "outside_paraphrases.jsonl"


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
    """What the reader did with one line, and how that compares with the label.

    A line with a danger label is in scope: reading it faithfully means composing that danger on the
    labelled object, either a catalogue name or, for a free word ("oven cleaner"), a proxy shape of its
    kind that keeps the user's word (``Mention.called``). Refusing it is a wrong refusal. A line with
    no danger label is out of scope and should be refused; composing it is a substitution."""
    from anomalygen.brainstorm.line_compose import Refused
    from anomalygen.knowledge.grounding import normalise

    objects = [o for o in row["object"] if o in kb.objects]
    free = [normalise(o) for o in row["object"] if o not in kb.objects]
    expect_refusal = not row["danger"]
    out = {"id": row["id"], "half": row["half"], "source": source_of(row), "line": row["line"],
           "in_scope": not expect_refusal}
    try:
        _, comp = tg.compose(row["line"])
    except Refused as exc:
        out.update(outcome="refused", reason=str(exc), verdict="faithful" if expect_refusal else "wrong_refusal")
        if not expect_refusal:
            out["refusal_type"] = _refusal_type(str(exc))
        return out
    mech = comp.hc.composition.mechanism
    called = normalise(comp.fault.called) if getattr(comp.fault, "called", None) else None  # (older readers lack it)
    said_as_labelled = called is not None and any(f == called or f.endswith("_" + called) or called.endswith("_" + f)
                                                  for f in free)
    right_object = comp.fault.name in objects or said_as_labelled
    ok = not expect_refusal and right_object and mech in row["danger"]
    # the task the line becomes must put the state on that object too: a class about its target
    # (left on, left open) sets it on the task's target_asset
    task = tg.proposal(row["line"], 1)
    built_on = task.target_asset if comp.hc.about_target else task.scenario.hazard_object
    ok = ok and built_on == comp.fault.name
    if not ok:
        out["substitution_type"] = ("out of scope, composed" if expect_refusal else
                                    "the task's object is not the one read" if right_object and mech in row["danger"] else
                                    "another danger" if right_object else
                                    "another object" if mech in row["danger"] else "another object and danger")
    out.update(outcome="composed", hazard_class=comp.hc.id, mechanism=mech, object=comp.fault.name,
               called=getattr(comp.fault, "called", None), other=comp.other.name if comp.other else None, built_on=built_on,
               verdict="faithful" if ok else "substitution")
    missing = [n for n in (comp.fault.name, comp.other.name if comp.other else None) if n and n not in tg_catalogue()]
    out["needs_assets"] = missing
    return out


def _refusal_type(reason: str) -> str:
    """A refusal's reason as a type (what was missing), so a half is described without its lines."""
    if reason.startswith("no object"):
        return "a word neither the catalogue nor the lexicon holds"
    if reason.startswith("no mechanism puts"):
        return "no mechanism for the object's kinds"
    if reason.startswith("no mechanism for") and "(needs " in reason:
        return "a mechanism's place or state not read: needs " + reason.rsplit("(needs ", 1)[1].rstrip(")")
    return "other: " + reason.split(" (the line says")[0].split(":")[0][:60]


def reading(line: str, tg) -> tuple:
    """What a line reads as, in the terms a paraphrase must keep: refused, or the composed class with
    its object at fault (shape and kind), the related object and how it relates."""
    from anomalygen.brainstorm.line_compose import Refused

    try:
        _, comp = tg.compose(line)
    except Refused:
        return ("refused",)
    other = comp.other
    return (comp.hc.id, _object_identity(comp.fault), _object_identity(other) if other else None,
            other.relation if other else None)


def _object_identity(m) -> frozenset:
    """An object as a paraphrase must keep it: its catalogue shape, or any kind of the lexicon it is
    (a proxy's kind, or every kind the shape stands for), so "pills" and "tablets" are one object."""
    try:
        from anomalygen.knowledge.lexicon import load_lexicon
    except ImportError:  # a reader from before the lexicon
        return frozenset({m.name})
    kinds = {k.id for k in load_lexicon().kinds.values() if m.name in k.proxies}
    own = getattr(m, "kind", None)
    return frozenset({own} if own else kinds or {m.name})


def _same(a: tuple, b: tuple) -> bool:
    if len(a) != len(b) or a[0] != b[0]:
        return False
    if len(a) == 1:
        return True
    return bool(a[1] & b[1]) and ((a[2] is None) == (b[2] is None)) and (a[2] is None or bool(a[2] & b[2])) \
        and a[3] == b[3]


def paraphrase_agreement(rows: list[dict], tg) -> dict:
    """Per half: lines whose every paraphrase reads as the line does (``reading``), and paraphrases that do."""
    by_id = {json.loads(x)["id"]: json.loads(x)["paraphrases"]
             for x in PARAPHRASES.read_text(encoding="utf-8").splitlines() if x.strip()} if PARAPHRASES.exists() else {}
    out: dict[str, dict] = {}
    for r in rows:
        alts = by_id.get(r["id"])
        if not alts:
            continue
        base = reading(r["line"], tg)
        same = [_same(reading(a, tg), base) for a in alts]
        for key in ("all", r["half"]):
            t = out.setdefault(key, {"lines": 0, "lines_all_same": 0, "paraphrases": 0, "paraphrases_same": 0})
            t["lines"] += 1
            t["lines_all_same"] += all(same)
            t["paraphrases"] += len(same)
            t["paraphrases_same"] += sum(same)
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
        "in_scope": sum(r["in_scope"] for r in results),
        "in_scope_faithful": sum(r["in_scope"] and r["verdict"] == "faithful" for r in results),
        "out_of_scope": sum(not r["in_scope"] for r in results),
        "out_of_scope_refused": sum(not r["in_scope"] and r["outcome"] == "refused" for r in results),
        "substitution_types": dict(Counter(r["substitution_type"] for r in results if "substitution_type" in r
                                           and r["verdict"] == "substitution").most_common()),
        "wrong_refusal_types": dict(Counter(r["refusal_type"] for r in results if "refusal_type" in r).most_common()),
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
    ap.add_argument("--lines", action="store_true", help="print every line's outcome (dev half only)")
    ap.add_argument("--paraphrases", action="store_true", help="also score agreement across paraphrases")
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
    # line by line only for the development half: the held-out half is scored in aggregate alone
    dev = [r for r in results if r["half"] == "dev"]
    report["refusal_reasons"] = {r["id"]: r["reason"] for r in dev if r["outcome"] == "refused"}
    report["substitutions"] = {r["id"]: f"{r['object']} / {r['mechanism']} ({r['hazard_class']})"
                               for r in dev if r["verdict"] == "substitution"}
    if args.paraphrases:
        report["paraphrases"] = paraphrase_agreement(rows, tg)
    if args.build:
        buildable = [r["line"] for r in results if r["verdict"] == "faithful" and r["outcome"] == "composed"
                     and not r.get("needs_assets")]
        report["pipeline"] = run_pipeline(buildable, args.out, args.workers)
    if args.lines:
        for r in dev:
            what = r.get("reason") or f"{r['object']} / {r['mechanism']} / {r['hazard_class']}"
            print(f"{r['id']} {r['half']:8s} {r['verdict']:13s} {what[:90]} | {r['line']}")
    if args.json:
        print(json.dumps(report))
        return
    for name, t in [("all", report["set"]), *report["halves"].items()]:
        print(f"{name:9s} lines {t['lines']:3d}  faithful {t['faithful']:3d} ({t['faithful_pct']:5.1f} %)  "
              f"substitutions {t['substitutions']:2d} ({t['substitution_pct']:4.1f} %)  wrong refusals {t['wrong_refusals']:2d}  "
              f"refused {t['refused']:2d}  composed {t['composed']:2d} (needing assets {t['composed_needing_assets']})")
        print(f"{'':9s} in scope {t['in_scope']:3d}: {t['in_scope_faithful']:3d} faithful; out of scope "
              f"{t['out_of_scope']:2d}: {t['out_of_scope_refused']:2d} refused")
    for name, t in report["halves"].items():
        print(f"{name:9s} substitutions by type: {t['substitution_types']}")
        print(f"{'':9s} wrong refusals by type: {t['wrong_refusal_types']}")
    print("per source:")
    for s, t in report["sources"].items():
        print(f"  {s:40s} {t['faithful']:2d}/{t['lines']:2d} faithful, {t['substitutions']} substituted, "
              f"{t['wrong_refusals']} wrongly refused")
    print("refused lines (dev half):")
    for rid, reason in report["refusal_reasons"].items():
        print(f"  {rid}: {reason}")
    if report["substitutions"]:
        print("substitutions (dev half):")
        for rid, what in report["substitutions"].items():
            print(f"  {rid}: {what}")
    for half, t in report.get("paraphrases", {}).items():
        print(f"paraphrases {half:8s}: {t['lines_all_same']}/{t['lines']} lines read the same in every paraphrase; "
              f"{t['paraphrases_same']}/{t['paraphrases']} paraphrases read as their line")
    if "pipeline" in report:
        print("pipeline:", json.dumps(report["pipeline"]))


if __name__ == "__main__":
    main()
