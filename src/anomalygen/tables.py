"""Terminal tables whose first column holds names that must stay whole (hazard classes, categories).

Why: rich shrinks every column of a table wider than the terminal and cuts text with an ellipsis,
so at 80 columns ``keep_medicine_out_of_reach`` became ``keep_medicine_o…``. Here the name column
never wraps or shrinks below its longest entry; the figure columns fold instead (short headers keep
that rare). Group rows (a category) come first, each followed by its own members, indented.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

INDENT = "  "  # members under their group


def name_table(title: str, name_header: str, columns: Sequence[str], names: Sequence[str]):
    """An empty rich Table: the name column as wide as the longest of ``names``, the rest folding."""
    from rich.table import Table

    table = Table(title=title, title_justify="left", collapse_padding=True)
    width = max([len(name_header), *(len(n) for n in names)])
    table.add_column(name_header, no_wrap=True, min_width=width, overflow="fold")
    for col in columns:
        table.add_column(col, justify="right", overflow="fold")
    return table


def group_table(title: str, columns: Sequence[str], rows: Mapping[str, Sequence[tuple[str, Sequence[str]]]],
                totals: Mapping[str, Sequence[str]] | None = None, *, overall: Sequence[str] | None = None,
                name_header: str = "category / hazard class"):
    """``rows``: group -> [(member, cells)]; ``totals``: group -> cells of its own row (blank without)."""
    names = [*rows, *(INDENT + m for members in rows.values() for m, _ in members), "all"]
    table = name_table(title, name_header, columns, names)
    blank = [""] * len(columns)
    if overall is not None:
        table.add_row("all", *overall, style="bold", end_section=True)
    for group, members in rows.items():
        table.add_row(group, *((totals or {}).get(group) or blank), style="bold cyan")
        for member, cells in members:
            table.add_row(INDENT + member, *cells)
    every = [*(cells for members in rows.values() for _, cells in members), *(totals or {}).values(), overall or []]
    for i, col in enumerate(table.columns[1:]):  # a figure stays on one line ("2/3 (67%)"); headers fold
        col.min_width = max((len(str(cells[i])) for cells in every if cells and i < len(cells)), default=0)
    return table


def print_with_total(table, rows: Mapping[str, Mapping[str, float]], counts: Sequence[str], cells) -> None:
    """Add one row per name of ``rows`` and a total row ``all`` (the sum of ``counts`` over them), each
    made by ``cells(name, row)``, and print the table on stderr."""
    from rich.console import Console

    for name, row in rows.items():
        table.add_row(*cells(name, row))
    table.add_row(*cells("all", {k: sum(r[k] for r in rows.values()) for k in counts}))
    Console(stderr=True).print(table)
