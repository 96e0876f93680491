"""``anomalygen assets ...``: list, show, render, validate, search and gallery.

Imports of MuJoCo and Sentence-BERT happen inside the commands, so ``anomalygen --help`` stays fast.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.table import Table

from anomalygen.errors import UserError

app = typer.Typer(help="Asset library: list, show, render, validate, search, gallery.", no_args_is_help=True)
out = Console()


def _check_name(name: str) -> str:
    from anomalygen.assets.core import available_names

    names = available_names()
    if name in names:
        return name
    lower = {n.lower(): n for n in names}
    if name.lower() in lower:
        return lower[name.lower()]
    raise UserError(f"unknown asset name {name!r}; see 'anomalygen assets list'")


def _png_out(path: Path) -> Path:
    """An ``--out`` path a PNG can be written to, checked before the rendering starts: a folder there
    is one line (the write would otherwise fail after the work, with a traceback)."""
    if path.is_dir():
        raise UserError(f"{path}: a folder; give --out the PNG file's path, e.g. {path / 'out.png'}")
    return path


@app.command("list")
def list_cmd(
    json_out: Annotated[bool, typer.Option("--json", help="Machine-readable output.")] = False,
) -> None:
    """Every asset name with its kind, plausible size range, and where its models come from (the
    procedural generator and/or packaged real models, each with its licence)."""
    from anomalygen.assets.core import sources
    from anomalygen.assets.names import group, household_names, size_range, target_names

    rows = [
        {"name": n, "kind": kind, "group": group(n), "size_range": size_range(n), **sources(n)}
        for kind, names in (("target", target_names()), ("household", household_names()))
        for n in names
    ]
    if json_out:
        print(json.dumps(rows))
        return
    t = Table("name", "kind", "group", "size (m)", "sources (licence)")
    for r in rows:
        t.add_row(r["name"], r["kind"], r["group"], f"{r['size_range'][0]:.3g}-{r['size_range'][1]:.3g}",
                  ", ".join(f"{s['source']} ({s['licence']})" for s in r["sources"]))
    out.print(t)
    real = [r for r in rows if r["real_models"]]
    out.print(f"{len(rows)} names ({sum(r['kind'] == 'target' for r in rows)} target categories); "
              f"{len(real)} with real models ({sum(r['kind'] == 'target' for r in real)} targets)")


@app.command()
def show(
    name: str,
    seed: Annotated[int, typer.Option(help="Variant seed.")] = 0,
    size: Annotated[float | None, typer.Option(help="Largest dimension in metres.")] = None,
    real: Annotated[bool, typer.Option("--real", help="The real model a scene draws for this seed, if any.")] = False,
    json_out: Annotated[bool, typer.Option("--json")] = False,
) -> None:
    """Facts about one asset variant: size, mass, joints, surfaces, cavities, description."""
    from anomalygen.assets.core import draw

    a = draw(_check_name(name), seed, size, real=real)
    info = {
        "asset_id": a.asset_id,
        "category": a.category,
        "source": str(a.source),
        "package": a.package,
        "licence": a.licence,
        "size": round(a.size, 4),
        "aabb": [a.aabb[0].round(4).tolist(), a.aabb[1].round(4).tolist()],
        "mass": round(a.mass, 4),
        "joints": [
            {
                "name": j.name,
                "type": j.type,
                "label": j.label,
                "range": [round(v, 4) for v in j.range],
                "closed": round(j.closed_value, 4),
            }
            for j in a.joints
        ],
        "surfaces": [
            {
                "name": s.name,
                "center": [round(v, 4) for v in s.center],
                "half_size": [round(v, 4) for v in s.half_size],
            }
            for s in a.surfaces
        ],
        "cavities": [
            {
                "name": c.name,
                "opening": c.opening,
                "joint": c.joint,
                "center": [round(v, 4) for v in c.center],
                "half_extents": [round(v, 4) for v in c.half_extents],
            }
            for c in a.cavities
        ],
        "description": a.description,
        "params": a.params,
    }
    if json_out:
        print(json.dumps(info))
        return
    for k, v in info.items():
        out.print(f"[bold]{k}[/bold]: {v}")


@app.command()
def render(
    name: str,
    seed: Annotated[int, typer.Option(help="Variant seed.")] = 0,
    out_path: Annotated[Path, typer.Option("--out", "-o", help="PNG file to write.")] = Path("asset.png"),
    open_fraction: Annotated[float, typer.Option("--open", help="Pose joints this far open (0..1).")] = 0.3,
    width: int = 480,
    height: int = 360,
    real: Annotated[bool, typer.Option("--real", help="The real model a scene draws for this seed, if any.")] = False,
) -> None:
    """Render one asset variant to a PNG."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    from anomalygen.assets.core import draw
    from anomalygen.assets.render import render_asset, save_png

    _png_out(out_path)
    a = draw(_check_name(name), seed, real=real)
    save_png(render_asset(a, width=width, height=height, open_fraction=open_fraction), out_path)
    out.print(f"wrote {out_path}")


def _validate_one(args: tuple[str, int | str, bool]) -> dict:
    """One asset's checks: ``seed`` an int is a procedural seed, a str a packaged model's key."""
    from anomalygen.assets.core import generate
    from anomalygen.assets.real.catalogue import build, by_key
    from anomalygen.assets.validate import validate_asset

    name, seed, do_render = args
    try:
        asset = build(by_key(seed)) if isinstance(seed, str) else generate(name, seed)
        r = validate_asset(asset, render=do_render)
        return {"name": name, "seed": seed, "ok": r.ok, "reason": r.reason}
    except Exception as exc:  # a generator crash is a failed item, not a failed run
        return {"name": name, "seed": seed, "ok": False, "reason": f"{type(exc).__name__}: {exc}"[:300]}


@app.command()
def validate(
    per_category: Annotated[int, typer.Option("--per-category", "-n", help="Seeds per name.")] = 10,
    names: Annotated[list[str] | None, typer.Option("--name", help="Only these names (repeatable).")] = None,
    household: Annotated[
        bool,
        typer.Option("--household/--targets", help="Validate household objects instead of the 44 targets."),
    ] = False,
    do_render: Annotated[
        bool, typer.Option("--render/--no-render", help="Also render a thumbnail per asset.")
    ] = True,
    workers: Annotated[int, typer.Option("--workers", "-j", help="Parallel processes.")] = 1,
    real: Annotated[
        bool, typer.Option("--real", help="Validate every packaged real model (of the --name ones, or all) once.")
    ] = False,
    json_out: Annotated[bool, typer.Option("--json")] = False,
) -> None:
    """Compile, rest on the floor for 2 s, sweep every joint, render: per name over seeds 0..n-1
    (with --real: each packaged model of each name)."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    from anomalygen.assets.core import real_models
    from anomalygen.assets.names import household_names, target_names
    from anomalygen.assets.real.catalogue import by_category

    if real:
        todo_names = [_check_name(n) for n in names] if names else sorted(by_category())
        jobs = [(n, m.key, do_render) for n in todo_names for m in real_models(n)]
    else:
        todo_names = (
            [_check_name(n) for n in names] if names else (household_names() if household else target_names())
        )
        jobs = [(n, s, do_render) for n in todo_names for s in range(per_category)]
    t0 = time.perf_counter()
    if workers > 1:
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor

        with ProcessPoolExecutor(workers, mp_context=mp.get_context("spawn")) as pool:
            results = list(pool.map(_validate_one, jobs, chunksize=4))
    else:
        results = []
        with out.status("validating") as status:
            for i, job in enumerate(jobs):
                status.update(f"validating {job[0]} seed {job[1]} ({i + 1}/{len(jobs)})")
                results.append(_validate_one(job))
    per = {n: [r for r in results if r["name"] == n] for n in todo_names}
    passed = [n for n, rs in per.items() if all(r["ok"] for r in rs)]
    wall = time.perf_counter() - t0
    summary = {
        "names": len(todo_names),
        "passed": len(passed),
        "assets": len(results),
        "assets_ok": sum(r["ok"] for r in results),
        "wall_s": round(wall, 1),
        "failures": [r for r in results if not r["ok"]],
    }
    if json_out:
        print(json.dumps(summary))
    else:
        for f in summary["failures"]:
            out.print(f"[red]FAIL[/red] {f['name']} {'model' if real else 'seed'} {f['seed']}: {f['reason']}")
        out.print(
            f"{len(passed)}/{len(todo_names)} categories pass ({summary['assets_ok']}/{len(results)} assets, "
            f"{'every real model' if real else f'{per_category} seeds each'}) in {wall:.0f} s"
        )
    if len(passed) != len(todo_names):
        raise typer.Exit(1)


@app.command()
def search(
    query: str,
    k: Annotated[int, typer.Option("-k", help="How many results.")] = 5,
    category: Annotated[str | None, typer.Option(help="Only this category/name.")] = None,
    variants: Annotated[int, typer.Option(help="Catalogue variants per name.")] = 3,
    json_out: Annotated[bool, typer.Option("--json")] = False,
) -> None:
    """Sentence-BERT search of the catalogue descriptions."""
    from anomalygen.assets.retrieval import retrieve

    hits = retrieve(query, k, category, variants_per_name=variants)
    if json_out:
        print(
            json.dumps(
                [
                    {
                        "asset_id": e.asset_id,
                        "name": e.name,
                        "score": round(s, 4),
                        "size": e.size,
                        "description": e.description,
                    }
                    for e, s in hits
                ]
            )
        )
        return
    t = Table("score", "asset", "size (m)", "description")
    for e, s in hits:
        t.add_row(f"{s:.3f}", e.asset_id, f"{e.size:.3f}", e.description[:90])
    out.print(t)


@app.command()
def gallery(
    out_path: Annotated[Path, typer.Option("--out", "-o", help="PNG file to write.")] = Path("gallery.png"),
    seed: Annotated[int, typer.Option(help="Variant seed.")] = 0,
    cell: Annotated[int, typer.Option(help="Thumbnail size in pixels.")] = 200,
    household: Annotated[bool, typer.Option("--household/--targets")] = False,
    real: Annotated[bool, typer.Option("--real", help="Every name with a real model, drawn as a scene would.")] = False,
) -> None:
    """Contact sheet of all 44 target categories (or the household objects), labelled."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    from anomalygen.assets.names import household_names, target_names
    from anomalygen.assets.real.catalogue import by_category
    from anomalygen.assets.render import gallery as make_gallery
    from anomalygen.assets.render import save_png

    _png_out(out_path)
    names = household_names() if household else target_names()
    if real:
        names = [n for n in target_names() + household_names() if n in by_category()]
    save_png(make_gallery(names, seed, cell=cell, cols=8 if not household else 10, real=real), out_path)
    out.print(f"wrote {out_path} ({len(names)} assets)")
