"""Command-line interface: one subcommand per stage plus assets, schema, config and llm tools.

Heavy imports (torch, MuJoCo, sentence-transformers) happen inside commands, so ``--help`` is instant.
User mistakes end as one red line and exit code 2, never a traceback.
"""

from __future__ import annotations

import contextlib
import importlib
import json
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.console import Console

from anomalygen.errors import AnomalygenError, UserError

if TYPE_CHECKING:
    from anomalygen.config import Settings

app = typer.Typer(
    name="anomalygen",
    help="Generate household hazards, build them in MuJoCo, detect and resolve them with a robot, and measure it.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    add_completion=False,
)
config_app = typer.Typer(help="Inspect the effective configuration.", no_args_is_help=True)
app.add_typer(config_app, name="config")

out = Console()
err = Console(stderr=True)

# ----------------------------------------------------------------------------- shared options

ConfigOpt = Annotated[Path | None, typer.Option("--config", "-c", help="TOML config file.")]
RunOpt = Annotated[Path, typer.Option("--run", "--out", "-r", help="Run folder.")]
SeedOpt = Annotated[int | None, typer.Option(help="Master seed.")]
ForceOpt = Annotated[bool, typer.Option("--force", help="Redo items whose outputs already exist.")]
QuietOpt = Annotated[bool, typer.Option("--quiet", "-q", help="No progress bars.")]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print a machine-readable JSON summary.")]
OnlyOpt = Annotated[list[str] | None, typer.Option("--only", help="Only these task ids (repeatable).")]
WorkersOpt = Annotated[int | None, typer.Option("--workers", "-j", help="Parallel worker processes.")]
ExecutorOpt = Annotated[str | None, typer.Option("--executor", help="local or ray.")]
AddressOpt = Annotated[str | None, typer.Option("--address", help="Ray cluster address.")]
NoCacheOpt = Annotated[bool, typer.Option("--no-cache", help="Bypass the LLM response cache.")]
BackendOpt = Annotated[str | None, typer.Option("--backend", help="LLM backend: openai, anthropic, llamacpp.")]
ModelOpt = Annotated[str | None, typer.Option("--model", help="LLM model name (or GGUF path for llamacpp).")]


def _settings(config: Path | None, **overrides: Any):
    from anomalygen.config import load_settings

    return load_settings(config, overrides)


def _common(
    config, seed=None, quiet=False, workers=None, executor=None, address=None, no_cache=False, backend=None, model=None, **more
):
    overrides = {
        "seed": seed,
        "quiet": quiet or None,
        "workers": workers,
        "executor": executor,
        "ray_address": address,
        "llm.cache": False if no_cache else None,
        "llm.backend": backend,
    }
    if model is not None:
        overrides["llm.model_path" if (backend == "llamacpp" or model.endswith(".gguf")) else "llm.model"] = model
    overrides.update(more)
    return _settings(config, **overrides)


def _run_stage(name: str, run, settings: Settings, **kwargs):
    """Run a registered stage (``anomalygen.stages``, the list ``anomalygen run`` also follows)."""
    from anomalygen.stages import stage

    return stage(name).run(run, settings, **kwargs)


@contextlib.contextmanager
def _json_stdout(as_json: bool):
    """With ``--json``, stdout carries the JSON and nothing else: while the command runs, whatever else
    is written there (a library's print, C code, a child process) goes to stderr. Yields the stream
    the JSON goes to."""
    if not as_json:
        yield sys.stdout
        return
    saved = sys.stdout
    saved.flush()
    try:
        on_fd1 = saved.fileno() == 1
    except (AttributeError, ValueError, OSError):  # a captured or replaced stream: Python-level only
        on_fd1 = False
    json_fd = os.dup(1) if on_fd1 else None
    if json_fd is not None:
        os.dup2(2, 1)
    out = os.fdopen(os.dup(json_fd), "w") if json_fd is not None else saved
    try:
        with contextlib.redirect_stdout(sys.stderr):
            yield out
    finally:
        out.flush()
        if json_fd is not None:
            out.close()
            sys.stderr.flush()
            os.dup2(json_fd, 1)
            os.close(json_fd)


def _stage(name: str, run, settings: Settings, as_json: bool, **kwargs) -> None:
    """Run a registered stage and report it (``--json``: the summary alone on stdout)."""
    with _json_stdout(as_json) as out:
        _finish(_run_stage(name, run, settings, **kwargs), as_json, out)


def _finish(summary, as_json: bool, out=None) -> None:
    from rich.markup import escape
    if as_json:
        payload = {
            "stage": summary.stage,
            "done": summary.done,
            "skipped": summary.skipped,
            "failed": summary.failed,
            "wall_s": round(summary.wall_s, 3),
            "errors": summary.errors,
        }
        print(json.dumps(payload, indent=2), file=out or sys.stdout, flush=True)
    else:
        err.print(summary.line())
        for item_id, reason in list(summary.errors.items())[:10]:
            err.print(f"  [red]✗[/red] {item_id}: {escape(reason)}", highlight=False, soft_wrap=True)
        if len(summary.errors) > 10:
            err.print(f"  ... {len(summary.errors) - 10} more in errors/{summary.stage}/")
    if summary.failed and not summary.done and not summary.skipped:
        raise typer.Exit(1)


def _open_run(path: Path):
    from anomalygen.runfolder import RunFolder

    return RunFolder.open(path)


def _create_run(path: Path, settings: Settings, stages: tuple[str, ...] | None = None):
    """Create (or reopen) the run folder once the ``stages`` about to run (all, by default) have read
    the user's own input files: a bad one ends the command with one line before anything is written,
    so the folder is left as it was (no folder, manifest or tasks.jsonl for a run that failed on its
    input)."""
    from anomalygen.runfolder import RunFolder
    from anomalygen.stages import STAGES

    for s in STAGES:
        if stages is None or s.name in stages:
            s.check_inputs(settings)
    return RunFolder.create(path, settings=settings)


# ----------------------------------------------------------------------------- stages


@app.command()
def brainstorm(
    run: RunOpt = Path("runs/default"),
    engine: Annotated[str | None, typer.Option(help="knowledge or llm.")] = None,
    mode: Annotated[str | None, typer.Option(help="plain, roleplay or brainstorm.")] = None,
    n: Annotated[int | None, typer.Option("--n", help="Number of proposals.")] = None,
    agents: Annotated[int | None, typer.Option(help="Number of role-playing agents.")] = None,
    rounds: Annotated[int | None, typer.Option(help="Brainstorming rounds.")] = None,
    tasks: Annotated[Path | None, typer.Option("--tasks", help="Bring your own tasks.jsonl instead.")] = None,
    tasks_text: Annotated[Path | None, typer.Option("--tasks-text", help="Plain descriptions, one per line, grounded into tasks.")] = None,
    config: ConfigOpt = None,
    seed: SeedOpt = None,
    force: ForceOpt = False,
    quiet: QuietOpt = False,
    as_json: JsonOpt = False,
    backend: BackendOpt = None,
    model: ModelOpt = None,
    no_cache: NoCacheOpt = False,
):
    """Stage 1: propose anomaly tasks (writes tasks.jsonl)."""
    settings = _common(
        config, seed, quiet, backend=backend, model=model, no_cache=no_cache,
        **{"brainstorm.engine": engine, "brainstorm.mode": mode, "brainstorm.n": n, "brainstorm.agents": agents,
           "brainstorm.rounds": rounds, "brainstorm.tasks_file": str(tasks) if tasks else None,
           "brainstorm.tasks_text": str(tasks_text) if tasks_text else None},
    )
    _stage("brainstorm", _create_run(run, settings, ("brainstorm",)), settings, as_json, force=force)


@app.command()
def build(
    run: RunOpt = Path("runs/default"),
    only: OnlyOpt = None,
    workers: WorkersOpt = None,
    clutter: Annotated[int | None, typer.Option(help="Unrelated objects added per scene.")] = None,
    engine: Annotated[str | None, typer.Option(help="Scene engine: knowledge (default) or llm.")] = None,
    config: ConfigOpt = None,
    seed: SeedOpt = None,
    force: ForceOpt = False,
    quiet: QuietOpt = False,
    as_json: JsonOpt = False,
    executor: ExecutorOpt = None,
    address: AddressOpt = None,
    backend: BackendOpt = None,
    model: ModelOpt = None,
):
    """Stage 2: build each task as a validated MuJoCo scene (writes scenes/<task_id>/)."""
    settings = _common(config, seed, quiet, workers, executor, address, backend=backend, model=model,
                       **{"build.clutter": clutter, "build.engine": engine})
    folder = _open_run(run)
    _stage("build", folder, settings, as_json, force=force, only=only)


@app.command()
def detect(
    run: RunOpt = Path("runs/default"),
    detector: Annotated[str | None, typer.Option(help="rules, llm or hybrid.")] = None,
    k: Annotated[int | None, typer.Option("--k", help="Hypotheses per scene.")] = None,
    noise: Annotated[bool | None, typer.Option(
        "--noise/--no-noise", help="Perception noise on the detectors' scene graph (settings: detect.noise).")] = None,
    only: OnlyOpt = None,
    config: ConfigOpt = None,
    force: ForceOpt = False,
    quiet: QuietOpt = False,
    as_json: JsonOpt = False,
    backend: BackendOpt = None,
    model: ModelOpt = None,
    no_cache: NoCacheOpt = False,
):
    """Stage 3: find the hazard in each scene without being told the task (writes detections.jsonl)."""
    settings = _common(config, None, quiet, backend=backend, model=model, no_cache=no_cache,
                       **{"detect.detector": detector, "detect.k": k, "detect.noise.enabled": noise})
    folder = _open_run(run)
    _stage("detect", folder, settings, as_json, force=force, only=only)


@app.command()
def plan(
    run: RunOpt = Path("runs/default"),
    source: Annotated[str | None, typer.Option(help="ground_truth or detected.")] = None,
    engine: Annotated[str | None, typer.Option(help="knowledge or llm.")] = None,
    only: OnlyOpt = None,
    config: ConfigOpt = None,
    force: ForceOpt = False,
    quiet: QuietOpt = False,
    as_json: JsonOpt = False,
    backend: BackendOpt = None,
    model: ModelOpt = None,
):
    """Stage 4a: decompose each fix into sub-tasks with rewards and success checks (writes plans/)."""
    settings = _common(config, None, quiet, backend=backend, model=model,
                       **{"plan.source": source, "plan.engine": engine})
    folder = _open_run(run)
    _stage("plan", folder, settings, as_json, force=force, only=only)


@app.command()
def learn(
    run: RunOpt = Path("runs/default"),
    sac_steps: Annotated[int | None, typer.Option("--sac-steps", help="SAC environment steps per sub-task.")] = None,
    seeds: Annotated[int | None, typer.Option("--seeds", help="Seeds per task.")] = None,
    only: OnlyOpt = None,
    workers: WorkersOpt = None,
    config: ConfigOpt = None,
    seed: SeedOpt = None,
    force: ForceOpt = False,
    quiet: QuietOpt = False,
    as_json: JsonOpt = False,
    executor: ExecutorOpt = None,
    address: AddressOpt = None,
):
    """Stage 4b: execute each plan (primitives, SAC, CEM) and check success (writes skills/)."""
    settings = _common(config, seed, quiet, workers, executor, address,
                       **{"learn.sac_steps": sac_steps, "learn.seeds": seeds})
    folder = _open_run(run)
    _stage("learn", folder, settings, as_json, force=force, only=only)


@app.command()
def judge(
    run: RunOpt = Path("runs/default"),
    only: OnlyOpt = None,
    workers: WorkersOpt = None,
    config: ConfigOpt = None,
    force: ForceOpt = False,
    quiet: QuietOpt = False,
    as_json: JsonOpt = False,
    executor: ExecutorOpt = None,
    address: AddressOpt = None,
):
    """The referee, after the robot: judge every run's released, settled final state against the hidden
    truth (writes skills/<task>/seed<k>/verdict.json)."""
    settings = _common(config, None, quiet, workers, executor, address)
    folder = _open_run(run)
    _finish(_run_stage("judge", folder, settings, force=force, only=only), as_json)


@app.command()
def evaluate(
    run: RunOpt = Path("runs/default"),
    config: ConfigOpt = None,
    quiet: QuietOpt = False,
    as_json: JsonOpt = False,
    no_images: Annotated[bool, typer.Option("--no-images", help="Skip image-embedding metrics.")] = False,
):
    """Measure diversity, detection hit@k and success; print the diversity table with baselines."""
    settings = _common(config, None, quiet, **{"evaluate.image_metrics": False if no_images else None})
    folder = _open_run(run)
    _stage("evaluate", folder, settings, as_json)


@app.command()
def report(
    run: RunOpt = Path("runs/default"),
    config: ConfigOpt = None,
    quiet: QuietOpt = False,
    as_json: JsonOpt = False,
):
    """Write report/index.html, report.json and summary.md for a run."""
    settings = _common(config, None, quiet)
    folder = _open_run(run)
    _stage("report", folder, settings, as_json)


@app.command("run")
def run_all(
    run: RunOpt = Path("runs/demo"),
    config: ConfigOpt = None,
    seed: SeedOpt = None,
    n: Annotated[int | None, typer.Option("--n", help="Number of tasks.")] = None,
    workers: WorkersOpt = None,
    executor: ExecutorOpt = None,
    address: AddressOpt = None,
    force: ForceOpt = False,
    quiet: QuietOpt = False,
    as_json: JsonOpt = False,
):
    """Run every stage end to end (resumable). Without a config: the embedded offline defaults."""
    from anomalygen.pipeline import demo_config_path, run_pipeline

    settings = _common(config or demo_config_path(), seed, quiet, workers, executor, address, **{"brainstorm.n": n})
    with _json_stdout(as_json) as stream:
        result = run_pipeline(_create_run(run, settings), settings, force=force)
        if as_json:
            print(json.dumps(result, indent=2, default=str), file=stream, flush=True)


# ----------------------------------------------------------------------------- tools


@app.command()
def schema(name: Annotated[str, typer.Argument(help="Artefact class, e.g. TaskProposal.")]):
    """Print the JSON Schema of an artefact."""
    from anomalygen.schema import ARTEFACTS

    matches = {k.lower(): v for k, v in ARTEFACTS.items()}
    cls = matches.get(name.lower())
    if cls is None:
        raise UserError(f"unknown artefact '{name}'; choose from: {', '.join(sorted(ARTEFACTS))}")
    print(json.dumps(cls.model_json_schema(), indent=2))


@config_app.command("show")
def config_show(config: ConfigOpt = None, as_json: JsonOpt = False):
    """Print the effective configuration (TOML < env < flags), secrets masked."""
    settings = _settings(config)
    data = settings.masked_dump()
    if as_json:
        print(json.dumps(data, indent=2))
    else:
        import tomli_w

        print(tomli_w.dumps(_drop_none(data)))


def _drop_none(d):
    if isinstance(d, dict):
        return {k: _drop_none(v) for k, v in d.items() if v is not None}
    return d


def _register_subapps() -> None:
    """Sub-apps owned by their packages (imported here; typer needs them to build the command tree)."""
    for name, module, help_text in (
        ("assets", "anomalygen.assets.cli", "Asset library: list, show, render, validate, search, gallery."),
        ("llm", "anomalygen.llm.cli", "Talk to the configured LLM: ping, ask."),
        ("suite", "anomalygen.bench.cli", "Frozen suites of built scenes: build, list, verify."),
    ):
        app.add_typer(importlib.import_module(module).app, name=name, help=help_text)
    # any agent over a suite, judged (docs/agents.md)
    app.command("bench")(importlib.import_module("anomalygen.bench.cli").bench)


_register_subapps()


def main(argv: list[str] | None = None) -> None:
    """Entry point: map expected errors to one line on stderr and a non-zero exit code."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])
    os.environ.setdefault("HF_HUB_OFFLINE", "1")
    os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
    os.environ.setdefault("TOKENIZERS_PARALLELISM", "false")
    from pydantic import ValidationError
    from rich.markup import escape

    from anomalygen.schema import format_validation_error

    try:
        app(args=argv, standalone_mode=False)
    except (AnomalygenError, ValidationError) as exc:
        msg = format_validation_error(exc) if isinstance(exc, ValidationError) else str(exc)
        err.print(f"[red]error:[/red] {escape(msg)}", highlight=False, soft_wrap=True)
        sys.exit(2)
    except typer.Exit as exc:
        sys.exit(exc.exit_code)
    except typer.Abort:
        err.print("[red]aborted[/red]")
        sys.exit(130)
    except Exception as exc:  # click usage errors (typer vendors click) arrive here in non-standalone mode
        if hasattr(exc, "show") and hasattr(exc, "exit_code"):
            exc.show()
            sys.exit(exc.exit_code)
        raise


if __name__ == "__main__":
    main()
