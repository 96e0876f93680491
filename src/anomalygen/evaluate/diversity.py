"""The diversity table: the run's tasks and the six public benchmarks measured alike, the paper's figures beside.

Every set, ours and each baseline, goes through ``text_draws.drawn_text_metrics`` on the same field
(the full description of each task), with the same draw size and number of draws, each set's draws
seeded by ``item_rng(seed, "text-draws", <set key>)``. The paper's figures stand in a column of their
own, "as published; not reproducible from public code"; its AnomalyGen row is its LLM engine's and
appears only as that, never beside our run as a target.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

from anomalygen.evaluate.baselines import BASELINES, PAPER_DIVERSITY, baseline_texts
from anomalygen.evaluate.html_parts import fmt
from anomalygen.evaluate.results import DiversityRow
from anomalygen.evaluate.text_draws import DRAW_SIZE, DRAWS, TEXT_FIELD, drawn_text_metrics
from anomalygen.evaluate.text_metrics import mean_wmd
from anomalygen.rng import item_rng

PUBLISHED_HEADER = "as published; not reproducible from public code"
PAPER_ENGINE_ROW = "AnomalyGen (the paper's LLM engine, GPT-4)"
DIVERSITY_HEADERS = ["set", "source", "n texts", "texts per draw", "Self-BLEU ↓ mean ± sd", "SBERT sim ↓ mean ± sd",
                     "image sim ↓", PUBLISHED_HEADER]
SOURCE_LABELS = {"run": "this run", "baseline": "public task list", "paper": "paper only"}


def text_row(name: str, kind: str, texts: Sequence[str], *, seed: int, key: str, draw_size: int = DRAW_SIZE,
             draws: int = DRAWS, wmd_pairs: int | None = None, timings: dict | None = None) -> DiversityRow:
    """Self-BLEU and SBERT of one set over its draws (seeded by ``key``); WMD on the whole set when asked."""
    timings = {} if timings is None else timings
    row = DiversityRow(name=name, kind=kind, tasks=len(texts), text_field=TEXT_FIELD, draw_size=draw_size)
    if len(texts) < 2:
        return row
    t0 = time.perf_counter()
    m = drawn_text_metrics(texts, rng=item_rng(seed, "text-draws", key), k=draw_size, draws=draws)
    timings["text_draws"] = round(timings.get("text_draws", 0.0) + time.perf_counter() - t0, 4)
    row.draws, row.small_set = m.draws, m.small_set
    row.self_bleu, row.self_bleu_std, row.self_bleu_95 = m.self_bleu.mean, m.self_bleu.std, (m.self_bleu.low, m.self_bleu.high)
    row.sbert, row.sbert_std, row.sbert_95 = m.sbert.mean, m.sbert.std, (m.sbert.low, m.sbert.high)
    if wmd_pairs is not None:
        t0 = time.perf_counter()
        row.wmd = mean_wmd(texts, rng=item_rng(seed, "wmd", key), max_pairs=wmd_pairs)
        timings["wmd"] = round(timings.get("wmd", 0.0) + time.perf_counter() - t0, 4)
    return row


def baseline_rows(*, seed: int, draw_size: int = DRAW_SIZE, draws: int = DRAWS, measure: bool = True,
                  timings: dict | None = None) -> list[DiversityRow]:
    """The paper's LLM-engine row (published only), then the six benchmarks, each with its published figures."""
    rows = [DiversityRow(name=PAPER_ENGINE_ROW, kind="paper", tasks=PAPER_DIVERSITY["AnomalyGen"].tasks,
                         published=PAPER_DIVERSITY["AnomalyGen"])]
    for stem, display in BASELINES.items():
        published = PAPER_DIVERSITY[display]
        if measure:
            row = text_row(display, "baseline", baseline_texts(stem), seed=seed, key=f"baseline:{stem}",
                           draw_size=draw_size, draws=draws, timings=timings)
        else:
            row = DiversityRow(name=display, kind="paper", tasks=published.tasks)
        row.published = published
        rows.append(row)
    return rows


def diversity_table(
    run_name: str,
    run_texts: Sequence[str],
    renders: Sequence[Path],
    *,
    seed: int,
    wmd_pairs: int,
    draw_size: int = DRAW_SIZE,
    draws: int = DRAWS,
    baselines: bool = True,
    image_metrics: bool = True,
    vit_weights: str | None = None,
    timings: dict | None = None,
    groups: dict[str, Sequence[str]] | None = None,
) -> list[DiversityRow]:
    """``run_texts``: the full description of each task. ``groups``: extra run rows, e.g. texts per
    brainstorm mode (the paper's ablation on one run); run rows also get WMD for that ablation."""
    timings = {} if timings is None else timings
    rows = []
    if run_texts:
        row = text_row(run_name, "run", run_texts, seed=seed, key="run", draw_size=draw_size, draws=draws,
                       wmd_pairs=wmd_pairs, timings=timings)
        if image_metrics and len(renders) >= 2:
            from anomalygen.evaluate.image_metrics import embedder_name, image_similarity

            t0 = time.perf_counter()
            row.image = image_similarity(renders, vit_weights=vit_weights)
            row.image_embedder = embedder_name(vit_weights)
            timings["image"] = round(time.perf_counter() - t0, 4)
        rows.append(row)
    for label, texts in (groups or {}).items():
        if len(texts) >= 2:
            rows.append(text_row(f"{run_name} [{label}]", "run", texts, seed=seed, key=f"run:{label}",
                                 draw_size=draw_size, draws=draws, wmd_pairs=wmd_pairs, timings=timings))
    rows += baseline_rows(seed=seed, draw_size=draw_size, draws=draws, measure=baselines, timings=timings)
    return rows


# --------------------------------------------------------------------------- the table's cells


def diversity_cells(rows: Sequence[DiversityRow]) -> list[list[str]]:
    """One line of strings per row under ``DIVERSITY_HEADERS`` (terminal, HTML and Markdown alike)."""
    return [[r.name, SOURCE_LABELS[r.kind], "—" if r.kind == "paper" else str(r.tasks), _per_draw(r),
             _mean_sd(r.self_bleu, r.self_bleu_std, r.draws), _mean_sd(r.sbert, r.sbert_std, r.draws),
             fmt(r.image), _published(r)] for r in rows]


def _per_draw(r: DiversityRow) -> str:
    if r.kind == "paper" or r.self_bleu is None:
        return "—"
    if r.draw_size is None:
        return f"all {r.tasks} (older file: whole set)"
    if r.small_set:
        return f"all {r.tasks} (flagged: fewer than {r.draw_size})"
    if (r.draws or 0) > 1:
        return f"{r.draw_size} × {r.draws} draws"
    return f"all {r.tasks}"


def _mean_sd(mean: float | None, sd: float | None, draws: int | None) -> str:
    if mean is None:
        return "—"
    return f"{mean:.3f} ± {sd:.3f}" if sd is not None and (draws or 0) > 1 else f"{mean:.3f}"


def _published(r: DiversityRow) -> str:
    p = r.published
    if p is None:
        return "—"
    return f"Self-BLEU {p.self_bleu:.3f} · SBERT {p.sbert:.3f} · ViT {p.vit:.3f} · CLIP {p.clip:.3f} ({p.tasks} tasks)"


def table_note(rows: Sequence[DiversityRow]) -> str:
    """What the table measures, in one paragraph (terminal caption, report note)."""
    measured = [r for r in rows if r.kind != "paper" and r.draw_size is not None and r.self_bleu is not None]
    sizes = sorted({(r.draw_size, r.draws) for r in measured if (r.draws or 0) > 1})
    draw = ", ".join(f"{k} texts × {n} draws" for k, n in sizes) or "whole sets"
    embedders = sorted({r.image_embedder for r in rows if r.kind == "run" and r.image_embedder})
    return (f"Text = the full description of each task (the same field for every set), Self-BLEU (NLTK-equal) and "
            f"mean pairwise SBERT cosine over repeated draws without replacement ({draw}; mean ± sample sd; a set "
            f"with fewer texts is measured whole and flagged). Baselines come from the packaged public task lists. "
            f"The last column is the paper's figures: {PUBLISHED_HEADER} (no public code computes them, and on these "
            f"lists they differ, even in order). \"{PAPER_ENGINE_ROW}\" is the paper's LLM-engine figure, not a "
            f"target for the offline engine. Image similarity: this run's front renders, "
            f"{', '.join(embedders) or 'not measured'} (the paper used ViT and CLIP).")


def rich_table(rows: Sequence[DiversityRow]):
    """A rich Table for the terminal (lower is more diverse in every similarity column)."""
    from rich.table import Table

    table = Table(title="Diversity (lower Self-BLEU / SBERT / image similarity = more diverse)", caption=table_note(rows))
    for col in DIVERSITY_HEADERS:
        table.add_column(col, justify="left" if col in ("set", "source", "texts per draw", PUBLISHED_HEADER) else "right")
    for r, cells in zip(rows, diversity_cells(rows), strict=True):
        table.add_row(*cells, end_section=r.kind == "run")
    return table
