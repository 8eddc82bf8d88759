"""The escape study's figures (issue 33, item 3), drawn from plain data a trial store holds:
how often each planner family got out of each trap and through the paper's task.

:func:`escape_matrix`: a grid of cells, rows (planner families, or planners grouped by
family) against columns (problems), each cell coloured by the share of its seeds that were
planned and executed cleanly and labelled with the count (``17/20``) and, for a family, the
member that did best. A reader sees at a glance which family escapes where.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from matplotlib import colormaps
from matplotlib.colors import Normalize
from matplotlib.figure import Figure


@dataclass(frozen=True)
class Cell:
    """One cell: ``clean`` of ``seeds`` executed cleanly (``seeds`` 0: not run), and a
    note under the count (the best member of a family, "one run" for a deterministic
    planner)."""

    clean: int
    seeds: int
    note: str = ""


def escape_matrix(
    rows: Sequence[str],
    columns: Sequence[str],
    cells: Sequence[Sequence[Cell]],
    title: str,
    groups: Sequence[int] = (),
) -> Figure:
    """``cells[i][j]`` for row ``rows[i]`` and column ``columns[j]``: colour = share
    executed cleanly (0 red to 1 green; grey: not run), text = ``clean/seeds`` and the
    cell's note. ``groups``: row indices after which a line separates families."""
    n_r, n_c = len(rows), len(columns)
    fig = Figure(figsize=(1.25 * n_c + 3.2, 0.42 * n_r + 1.6), layout="constrained")
    ax = fig.add_subplot(1, 1, 1)
    share = np.full((n_r, n_c), np.nan)
    for i in range(n_r):
        for j in range(n_c):
            c = cells[i][j]
            if c.seeds:
                share[i, j] = c.clean / c.seeds
    cmap = colormaps["RdYlGn"].with_extremes(bad="#dddddd")
    image = ax.imshow(
        np.ma.masked_invalid(share), cmap=cmap, norm=Normalize(0.0, 1.0), aspect="auto"
    )
    for i in range(n_r):
        for j in range(n_c):
            c = cells[i][j]
            text = "–" if not c.seeds else f"{c.clean}/{c.seeds}"
            if c.note and c.seeds:
                text += f"\n{c.note}"
            ax.text(j, i, text, ha="center", va="center", fontsize=6.5 if c.note else 8)
    for g in groups:
        ax.axhline(g + 0.5, color="black", lw=1.2)
    ax.set_xticks(
        range(n_c), [c.removeprefix("armz_") for c in columns], rotation=30, ha="right", fontsize=8
    )
    ax.set_yticks(range(n_r), rows, fontsize=8)
    ax.set_xticks(np.arange(n_c + 1) - 0.5, minor=True)
    ax.set_yticks(np.arange(n_r + 1) - 0.5, minor=True)
    ax.grid(which="minor", color="white", lw=1.5)
    ax.tick_params(which="minor", length=0)
    bar = fig.colorbar(image, ax=ax, shrink=0.8)
    bar.set_label("share of seeds planned and executed cleanly", fontsize=8)
    ax.set_title(title, fontsize=10)
    return fig


__all__ = ["Cell", "escape_matrix"]
