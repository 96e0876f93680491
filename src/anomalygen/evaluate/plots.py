"""Matplotlib figures for the report, returned as base64 PNG so index.html stays self-contained.

Agg backend only (no display on CI machines); matplotlib's config/cache goes to a temp folder unless
``MPLCONFIGDIR`` is already set, because a read-only or shared $HOME must not break a report.
"""

from __future__ import annotations

import base64
import io
import os
import tempfile


def _pyplot():
    os.environ.setdefault("MPLCONFIGDIR", tempfile.mkdtemp(prefix="mpl-"))
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _encode(fig) -> str:
    plt = _pyplot()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100, bbox_inches="tight")
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def category_pie(categories: dict[str, int]) -> str | None:
    if not categories or sum(categories.values()) == 0:
        return None
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(4.5, 4.5))
    labels = [k.replace("_", " ") for k in categories]
    ax.pie(list(categories.values()), labels=labels, autopct="%1.0f%%", startangle=90, counterclock=False)
    ax.set_title("Tasks by hazard category")
    return _encode(fig)


def success_bars(rates: dict[str, tuple[int, int]], title: str, ylabel: str = "rate") -> str | None:
    """``rates``: label -> (successes, n); ``title`` says whose verdict and which runs."""
    if not rates:
        return None
    plt = _pyplot()
    labels = [k.replace("_", " ") for k in rates]
    values = [s / n if n else 0.0 for s, n in rates.values()]
    fig, ax = plt.subplots(figsize=(max(4.5, 0.9 * len(labels) + 2), 3.5))
    bars = ax.bar(labels, values, color="#4c72b0")
    for bar, (s, n) in zip(bars, rates.values(), strict=False):
        ax.text(bar.get_x() + bar.get_width() / 2, bar.get_height() + 0.02, f"{s}/{n}" if n else "no runs",
                ha="center", fontsize=9)
    ax.set_ylim(0, 1.12)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.tick_params(axis="x", labelrotation=20)
    return _encode(fig)


def hit_at_k_plot(hit_at_k: dict[int, float], subset: str) -> str | None:
    """hit@k against the truth; ``subset`` names the scenes it covers (single-hazard ones)."""
    if not hit_at_k:
        return None
    plt = _pyplot()
    ks = sorted(hit_at_k)
    fig, ax = plt.subplots(figsize=(4.5, 3.5))
    ax.bar([str(k) for k in ks], [hit_at_k[k] for k in ks], color="#55a868")
    for i, k in enumerate(ks):
        ax.text(i, hit_at_k[k] + 0.02, f"{hit_at_k[k]:.2f}", ha="center", fontsize=9)
    ax.set_ylim(0, 1.12)
    ax.set_xlabel("k")
    ax.set_ylabel("fraction of scenes")
    ax.set_title(f"Detection hit@k against the truth\n({subset})")
    return _encode(fig)
