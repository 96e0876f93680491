"""``anomalygen suite build|list|verify`` and ``anomalygen bench``: thin commands over ``bench/``."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Annotated

import typer

app = typer.Typer(help="Frozen suites of built scenes: build, list, verify.", no_args_is_help=True)


def _settings(config: Path | None, **overrides):
    from anomalygen.config import load_settings

    return load_settings(config, {k: v for k, v in overrides.items() if v is not None})


@app.command("build")
def build(
    name: Annotated[str, typer.Argument(help="The suite's name (anomalygen suite list).")],
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Folder (default: the suite cache).")] = None,
    workers: Annotated[int | None, typer.Option("--workers", "-j", help="Parallel worker processes.")] = None,
    executor: Annotated[str | None, typer.Option("--executor", help="local or ray.")] = None,
    force: Annotated[bool, typer.Option("--force", help="Rebuild scenes already built.")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bars.")] = False,
):
    """Build a named suite reproducibly: its seed, its engine, the stages' defaults (your config does not enter)."""
    from anomalygen.bench.suites import build_suite, suite_def, suite_dir

    defn = suite_def(name)
    folder = out or suite_dir(defn.name, defn.version)
    m = build_suite(defn, folder, workers=workers, executor=executor, quiet=quiet, force=force)
    typer.echo(f"{defn.label}: {len(m.scenes)} of {m.tasks} tasks built into {folder}"
               + (f" (not built: {', '.join(m.not_built)})" if m.not_built else ""))


@app.command("list")
def list_suites():
    """The named suites, and whether each is built in the suite cache."""
    from anomalygen.bench.suites import SUITES, suite_dir
    from anomalygen.scene_files import SUITE_MANIFEST

    for s in SUITES.values():
        folder = suite_dir(s.name, s.version)
        state = f"built in {folder}" if (folder / SUITE_MANIFEST).is_file() else "not built"
        typer.echo(f"{s.name} (v{s.version}): {s.description}. {state}")


@app.command("verify")
def verify(suite: Annotated[str, typer.Argument(help="A suite's name or folder.")]):
    """Check every scene against the checksum its manifest recorded."""
    from anomalygen.bench.suites import open_suite, verify_suite

    s = open_suite(suite)
    problems = verify_suite(s)
    for p in problems:
        typer.echo(p, err=True)
    if problems:
        raise typer.Exit(1)
    typer.echo(f"{s.label}: {len(s.task_ids)} scenes as built")


def bench(
    agent: Annotated[str, typer.Option("--agent", help="MODULE:CLASS, e.g. anomalygen.agents:Pipeline.")],
    suite: Annotated[str, typer.Option("--suite", help="A suite's name (anomalygen suite list) or a built run folder.")],
    out: Annotated[Path | None, typer.Option("--out", "-o", help="Run folder (default runs/bench/<agent>-<suite>).")] = None,
    seeds: Annotated[int, typer.Option("--seeds", help="Episodes per scene.")] = 1,
    max_calls: Annotated[int | None, typer.Option("--max-calls", help="Calls per episode before it is cut off.")] = None,
    option: Annotated[list[str] | None, typer.Option("--option", help="KEY=VALUE for the agent's constructor (repeatable).")] = None,
    only: Annotated[list[str] | None, typer.Option("--only", help="Only these task ids (repeatable).")] = None,
    workers: Annotated[int | None, typer.Option("--workers", "-j", help="Parallel worker processes.")] = None,
    executor: Annotated[str | None, typer.Option("--executor", help="local or ray.")] = None,
    address: Annotated[str | None, typer.Option("--address", help="Ray cluster address.")] = None,
    config: Annotated[Path | None, typer.Option("--config", "-c", help="TOML config file.")] = None,
    force: Annotated[bool, typer.Option("--force", help="Redo episodes already judged.")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="No progress bars.")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Print the report as JSON on stdout.")] = False,
):
    """Run an agent over a suite in the skill-level env; print the referee's table, write bench.json and bench.html."""
    from anomalygen.bench.report import print_report
    from anomalygen.bench.run import run_bench
    from anomalygen.bench.suites import open_suite
    from anomalygen.scene_files import BENCH_PAGE

    settings = _settings(config, quiet=quiet or None, workers=workers, executor=executor, ray_address=address)
    s = open_suite(suite)
    folder = out or Path("runs") / "bench" / _slug(f"{agent.rsplit(':', 1)[-1]}-{Path(suite).name}")
    report = run_bench(agent, s, folder, settings, seeds=seeds, max_calls=max_calls, options=_options(option or []),
                       only=only, force=force)
    if as_json:
        typer.echo(json.dumps(report.model_dump(mode="json", exclude={"per_run"})))
    else:
        print_report(report)
        typer.echo(f"report: {folder / BENCH_PAGE}", err=True)


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "-", text).strip("-").lower()


def _options(pairs: list[str]) -> dict:
    from anomalygen.errors import UserError

    out = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key.isidentifier():
            raise UserError(f"--option takes KEY=VALUE, not {pair!r}")
        try:
            out[key] = json.loads(value)
        except json.JSONDecodeError:
            out[key] = value
    return out
