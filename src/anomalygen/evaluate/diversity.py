"""The diversity table: the run's tasks, the six public benchmarks and the paper's figures side by side."""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

from anomalygen.evaluate.baselines import BASELINES, PAPER_DIVERSITY, baseline_texts
from anomalygen.evaluate.results import DiversityRow
from anomalygen.evaluate.selfbleu import self_bleu
from anomalygen.evaluate.text_metrics import mean_wmd, sbert_similarity
from anomalygen.rng import item_rng


def text_row(name: str, kind: str, texts: Sequence[str], *, seed: int, wmd_pairs: int, timings: dict) -> DiversityRow:
    """Self-BLEU, SBERT similarity and WMD of one set of texts (WMD pairs seeded by the set's name)."""
    t0 = time.perf_counter()
    bleu = self_bleu(texts)
    t1 = time.perf_counter()
    sbert = sbert_similarity(texts)
    t2 = time.perf_counter()
    wmd = mean_wmd(texts, rng=item_rng(seed, "wmd", name), max_pairs=wmd_pairs)
    t3 = time.perf_counter()
    for key, dt in (("self_bleu", t1 - t0), ("sbert", t2 - t1), ("wmd", t3 - t2)):
        timings[key] = timings.get(key, 0.0) + round(dt, 4)
    return DiversityRow(name=name, kind=kind, tasks=len(texts), self_bleu=bleu, sbert=sbert, wmd=wmd)


def diversity_table(
    run_name: str,
    run_texts: Sequence[str],
    renders: Sequence[Path],
    *,
    seed: int,
    wmd_pairs: int,
    baselines: bool = True,
    image_metrics: bool = True,
    vit_weights: str | None = None,
    timings: dict | None = None,
    groups: dict[str, Sequence[str]] | None = None,
) -> list[DiversityRow]:
    """``groups``: extra run rows, e.g. texts per brainstorm mode (the paper's ablation on one run)."""
    timings = {} if timings is None else timings
    rows = []
    if run_texts:
        row = text_row(run_name, "run", run_texts, seed=seed, wmd_pairs=wmd_pairs, timings=timings)
        if image_metrics and len(renders) >= 2:
            from anomalygen.evaluate.image_metrics import embedder_name, image_similarity

            t0 = time.perf_counter()
            row.image = image_similarity(renders, vit_weights=vit_weights)
            row.image_embedder = embedder_name(vit_weights)
            timings["image"] = round(time.perf_counter() - t0, 4)
        rows.append(row)
    for label, texts in (groups or {}).items():
        if len(texts) >= 2:
            rows.append(text_row(f"{run_name} [{label}]", "run", texts, seed=seed, wmd_pairs=wmd_pairs, timings=timings))
    if baselines:
        for stem, display in BASELINES.items():
            rows.append(text_row(display, "baseline", baseline_texts(stem), seed=seed, wmd_pairs=wmd_pairs, timings=timings))
    for name, p in PAPER_DIVERSITY.items():
        rows.append(DiversityRow(name=f"{name} (paper)", kind="paper", tasks=p.tasks, self_bleu=p.self_bleu,
                                 sbert=p.sbert, image=p.vit, clip=p.clip, image_embedder="ViT / CLIP"))
    return rows


def rich_table(rows: Sequence[DiversityRow]):
    """A rich Table for the terminal (lower is more diverse in every similarity column)."""
    from rich.table import Table

    table = Table(title="Diversity (lower Self-BLEU / SBERT / image similarity and higher WMD = more diverse)")
    for col in ("set", "source", "tasks", "Self-BLEU", "SBERT sim", "WMD", "image sim", "CLIP sim"):
        table.add_column(col, justify="left" if col in ("set", "source") else "right")
    for r in rows:
        table.add_row(r.name, r.kind, str(r.tasks), _fmt(r.self_bleu), _fmt(r.sbert), _fmt(r.wmd), _fmt(r.image), _fmt(r.clip),
                      end_section=r.kind == "run")
    return table


def _fmt(x: float | None) -> str:
    return "—" if x is None else f"{x:.3f}"
