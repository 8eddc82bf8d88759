"""Figures of a study over many trials, drawn from plain data (times and goal distances a
comparison's trial store holds), never from a planner.

:func:`progress_panels`: one panel per problem, and in it, per planner, the median over its
seeds of the best goal distance reached by each moment (a seed that has finished keeps its
last value: 0 if it solved, its best distance if it gave up), so the figure shows when each
planner got out of the trap and how many of its seeds did.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib import colormaps
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

#: one seed's progress: rows of (time since the trial's first leg started [s], best goal
#: distance so far), times increasing; the last row is where the seed ended
SeedCurve = Sequence[tuple[float, float]]


def best_so_far(curve: SeedCurve, times_s: np.ndarray) -> np.ndarray:
    """One seed's best goal distance at each of ``times_s`` (NaN before its first row;
    after its last row, its last value)."""
    rows = np.asarray(curve, dtype=float).reshape(-1, 2)
    out = np.full(len(times_s), np.nan)
    if not len(rows):
        return out
    best = np.minimum.accumulate(rows[:, 1])
    idx = np.searchsorted(rows[:, 0], times_s, side="right") - 1
    have = idx >= 0
    out[have] = best[idx[have]]
    return out


def median_curve(curves: Sequence[SeedCurve], times_s: np.ndarray) -> np.ndarray:
    """The median over seeds of :func:`best_so_far` (seeds not yet started left out)."""
    if not curves:
        return np.full(len(times_s), np.nan)
    stack = np.vstack([best_so_far(c, times_s) for c in curves])
    out = np.full(len(times_s), np.nan)
    some = ~np.all(np.isnan(stack), axis=0)
    out[some] = np.nanmedian(stack[:, some], axis=0)
    return out


#: one colour per planner family (the name before its first "." or "+"; a name with a
#: "+" is a hybrid: one planner escaping with another)
FAMILY_COLOURS = {
    "gradient": "tab:blue",
    "hybrid": "tab:green",
    "ompl": "tab:orange",
    "follow_leader": "tab:purple",
    "native": "tab:brown",
    "chord_arc": "tab:pink",
}
#: members of one family: line styles, then markers on top
_STYLES = ("-", "--", ":", "-.")
_MARKERS = ("", "o", "s", "^", "v", "D")


def planner_family(name: str) -> str:
    """``gradient.clearance`` -> ``gradient``, ``ompl.prm`` -> ``ompl``, and every hybrid
    (``gradient+rrtconnect``, ``gradient.clearance+detour``) -> ``hybrid``."""
    return "hybrid" if "+" in name else name.split(".")[0]


def planner_styles(planners: Sequence[str]) -> dict[str, dict[str, object]]:
    """A line style per planner: its family's colour, and within the family a dash
    pattern (then a marker) of its own, so 14 planners stay apart in 4 to 6 colours."""
    spare = iter(colormaps["tab10"](range(10)))
    colours: dict[str, object] = {}
    out: dict[str, dict[str, object]] = {}
    count: dict[str, int] = {}
    for pl in sorted(planners):
        fam = planner_family(pl)
        if fam not in colours:
            colours[fam] = FAMILY_COLOURS.get(fam) or next(spare)
        k = count.get(fam, 0)
        count[fam] = k + 1
        out[pl] = {
            "color": colours[fam],
            "ls": _STYLES[k % len(_STYLES)],
            "marker": _MARKERS[(k // len(_STYLES)) % len(_MARKERS)],
            "markevery": 0.1,
            "ms": 3,
        }
    return out


def progress_panels(
    curves: Mapping[str, Mapping[str, Sequence[SeedCurve]]],
    title: str,
    t_max_s: float,
    columns: int = 3,
    ylabel: str = "median best goal distance [x tolerance; 0: in the goal]",
) -> Figure:
    """``curves[problem][planner]`` = the seeds' curves; one panel per problem, one line
    per planner (coloured by its family, :func:`planner_styles`, the same in every panel),
    time on a log axis from 10 ms to ``t_max_s``, the value (a goal distance, 0 in the
    goal region; or a task's legs still to go) on a linear axis from 0 (it is never
    negative)."""
    planners = sorted({pl for by_planner in curves.values() for pl in by_planner})
    style = planner_styles(planners)
    n = max(1, len(curves))
    rows = (n + columns - 1) // columns
    fig = Figure(figsize=(4.2 * columns, 3.2 * rows + 1.6), layout="constrained")
    times_s = np.geomspace(1e-2, t_max_s, 300)
    for k, (problem, by_planner) in enumerate(curves.items()):
        ax = fig.add_subplot(rows, columns, k + 1)
        for pl in planners:
            seeds = by_planner.get(pl)
            if not seeds:
                continue
            y = median_curve(seeds, times_s)
            ax.step(times_s, y, where="post", lw=1.4, label=pl, **style[pl])  # type: ignore[arg-type]
        ax.set_xscale("log")
        ax.set_ylim(bottom=0.0)
        ax.set_title(problem, fontsize=9)
        ax.grid(alpha=0.3)
        ax.set_xlabel("planning time [s]", fontsize=8)
        ax.set_ylabel(ylabel, fontsize=8)
        ax.tick_params(labelsize=7)
    handles = [Line2D([], [], lw=1.4, label=pl, **style[pl]) for pl in planners]  # type: ignore[arg-type]
    fig.legend(
        handles=handles,
        loc="outside lower center",
        ncols=4,
        fontsize=7,
        frameon=False,
        title="planner (colour: family; line style: member)",
        title_fontsize=7,
    )
    fig.suptitle(title, fontsize=10)
    return fig


__all__ = [
    "FAMILY_COLOURS",
    "SeedCurve",
    "best_so_far",
    "median_curve",
    "planner_family",
    "planner_styles",
    "progress_panels",
]
