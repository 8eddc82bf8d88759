"""Terminal tables that fit: one way to size the console and to build a table.

Numbers are never wrapped: numeric columns are ``no_wrap`` and right-aligned; names
(planners, goals, obstacles) are ``no_wrap`` with an ellipsis should the terminal be too
narrow; only prose (descriptions, reasons) wraps, at spaces. The console is as wide as
the terminal; when the output is piped it is as wide as ``COLUMNS`` says, else as the
terminal the command runs in (stderr's), else :data:`PIPE_WIDTH` columns.

``compare`` prints a compact table by default (:data:`COMPACT_COLUMNS`: planner, solved
with its 95 % interval, median time, median checks, local minima met/escaped, executed
cleanly) that fits 80 columns; ``--wide`` shows :data:`WIDE_COLUMNS` (path length with
its smoothness and its clearance along the path beside it, tip errors beside their
tolerances, …), ``--columns a,b`` picks from :data:`SUMMARY_COLUMNS`. A row is a
:class:`~plannerlab.comparison.statistics.SummaryRow`, read by attribute.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Literal, TextIO

from rich import box
from rich.console import Console
from rich.table import Table
from rich.text import Text

from plannerlab.errors import UnknownNameError
from plannerlab.record.cells import err_of_tol, fmt, mm, rough
from plannerlab.record.trial import reached_best

#: width of piped output when neither COLUMNS nor a terminal says otherwise
PIPE_WIDTH = 100

Kind = Literal["num", "name", "text"]


def output_width(stream: TextIO) -> int | None:
    """Columns for a console writing to ``stream``: None (rich asks the terminal) when it
    is a terminal; else ``COLUMNS``, else the width of the terminal on stderr or stdin,
    else :data:`PIPE_WIDTH`."""
    columns = os.environ.get("COLUMNS", "")
    if columns.strip().isdigit() and int(columns) > 0:
        return int(columns)
    try:
        if stream.isatty():
            return None
    except (AttributeError, ValueError):
        pass
    for fd in (2, 0):
        try:
            return os.get_terminal_size(fd).columns
        except OSError:
            continue
    return PIPE_WIDTH


def make_console(stderr: bool = False, stream: TextIO | None = None) -> Console:
    """The console of a command (stdout, or stderr when stdout carries JSON)."""
    import sys

    stream = stream or (sys.stderr if stderr else sys.stdout)
    # markup off: user text (paths, names, messages with "[table]" keys) prints as written;
    # styles are given as rich Text or style=, never as markup in a string. A line that
    # names a path prints with soft_wrap=True (never broken by an inserted newline)
    return Console(stderr=stderr, width=output_width(stream), markup=False)


def table(
    title: str | None,
    columns: Sequence[tuple[str, Kind]],
    *,
    compact: bool = False,
    caption: str | None = None,
) -> Table:
    """A table whose numbers never wrap. ``columns``: (header, kind) with kind ``num``
    (right-aligned, never wrapped), ``name`` (never wrapped, an ellipsis if it must be
    cut) or ``text`` (prose, wraps at spaces). ``compact``: no vertical rules, one space
    between columns."""
    t = Table(
        title=title,
        title_justify="left",
        caption=caption,
        caption_justify="left",
        box=box.SIMPLE_HEAD if compact else box.HEAVY_HEAD,
        show_edge=not compact,
        padding=(0, 1, 0, 0) if compact else (0, 1),
    )
    for header, kind in columns:
        if kind == "num":
            t.add_column(header, justify="right", no_wrap=True, overflow="ellipsis")
        elif kind == "name":
            t.add_column(header, no_wrap=True, overflow="ellipsis")
        else:
            t.add_column(header, overflow="fold")
    return t


# ---------------------------------------------------------------------- legs
#: what a leg's tip-error cells say when the leg has no best state (the reason says why)
NO_RESULT = "—"


def tip_error_cells(r: Any) -> tuple[str, str]:
    """A planned leg's (:class:`~plannerlab.record.leg.PlanResult`) tip errors as cells:
    each beside its goal tolerance (``0.0976 / 0.1``); :data:`NO_RESULT` for a leg that
    has no best state (it planned nothing or gave up: its last state is no result)."""
    if not reached_best(r.status, len(r.path)):
        return NO_RESULT, NO_RESULT
    return err_of_tol(r.pos_err_m, r.pos_tol_m), err_of_tol(r.angle_err_deg, r.angle_tol_deg)


def path_note(r: Any) -> str:
    """A solved leg's path quality for a table's caption: its smoothness and its smallest
    clearance along the whole path ("" when not measured)."""
    parts = []
    if r.roughness_rad2 == r.roughness_rad2:
        parts.append(f"smoothness {rough(r.roughness_rad2)} rad²")
    if r.path_clearance_m == r.path_clearance_m:
        parts.append(f"clearance along the path {fmt(mm(r.path_clearance_m))} mm")
    return "; " + ", ".join(parts) if parts else ""


# ---------------------------------------------------------------------- compare
@dataclass(frozen=True)
class SummaryColumn:
    """One column of ``compare``'s table: header, kind and the cell of a summary row."""

    header: str
    kind: Kind
    cell: Callable[[Any], str]
    help: str
    executed: bool = False  #: only meaningful when the comparison executed its plans


def _pct(x: Any) -> str:
    return "-" if x is None or x != x else f"{100 * x:.0f}"


def _solved(r: Any) -> str:
    return f"{r.successes}/{r.n}" + (f" ({r.errors} err)" if r.errors else "")


def _solved_ci(r: Any) -> str:
    # errors are listed under the table (and counted by ``solved_n``)
    if r.deterministic:
        return f"{r.successes}/{r.n} [{ONE_TRIAL}]"
    return f"{r.successes}/{r.n} [{_pct(r.ci95_low)}-{_pct(r.ci95_high)}%]"


def _success_ci(r: Any) -> str:
    if r.deterministic:
        return f"{_pct(r.success_rate)}% [{DETERMINISTIC}]"
    return f"{_pct(r.success_rate)}% [{_pct(r.ci95_low)}, {_pct(r.ci95_high)}]"


#: what stands where the interval would be when every seed ran the same trial (the
#: compact column has room for no more than an interval's width)
DETERMINISTIC = "deterministic"
ONE_TRIAL = "one trial"
_DETERMINISTIC_HELP = (
    "; [one trial] or [deterministic]: every seed gave the identical trial (same paths, "
    "counts and verdicts): the planner is deterministic here, the n seeds are one run "
    "and there is no interval"
)


def _exec_ok(r: Any) -> str:
    return f"{r.exec_successes}/{r.executed}" if r.executed else "-"


SUMMARY_COLUMNS: dict[str, SummaryColumn] = {
    "planner": SummaryColumn("planner", "name", lambda r: str(r.planner), "registry name"),
    "solved": SummaryColumn(
        "solved\n[95% CI]",
        "num",
        _solved_ci,
        "trials whose every leg is SOLVED, of n, with the Wilson 95 % interval"
        + _DETERMINISTIC_HELP,
    ),
    "solved_n": SummaryColumn("solved", "num", _solved, "solved trials of n"),
    "success": SummaryColumn(
        "success %\n[95% CI]",
        "num",
        _success_ci,
        "success rate with the Wilson 95 % interval" + _DETERMINISTIC_HELP,
    ),
    "time": SummaryColumn(
        "time s\nmedian", "num", lambda r: fmt(r.time_median_s), "planning time, median [s]"
    ),
    "time_p75_p95": SummaryColumn(
        "time s\np75 / p95",
        "num",
        lambda r: f"{fmt(r.time_p75_s)} / {fmt(r.time_p95_s)}",
        "planning time, 75th / 95th percentile [s]",
    ),
    "path": SummaryColumn(
        "path\nrad",
        "num",
        lambda r: fmt(r.path_length_median),
        "joint-space path length, median over solved trials [rad]",
    ),
    "smoothness": SummaryColumn(
        "smooth-\nness rad²",
        "num",
        lambda r: rough(r.smoothness_median_rad2),
        "the path's roughness: squared turning angles of each leg's path resampled at 200 "
        "states of equal joint-space arc length, summed over legs, median over solved "
        "trials [rad²]; lower is smoother",
    ),
    "path_clearance": SummaryColumn(
        "path clear.\nmin mm",
        "num",
        lambda r: fmt(mm(r.path_clearance_min_m)),
        "smallest clearance along the whole planned path (every state of the final "
        "re-check's grid, true geometry, to the scene and between links), over solved "
        "trials [mm]",
    ),
    "pos_err": SummaryColumn(
        "pos err\n/ tol m",
        "num",
        lambda r: err_of_tol(r.pos_err_median_m, r.pos_tol_m),
        "final tip position error of the last leg, median over solved trials, beside the "
        "goal's position tolerance [m]",
    ),
    "ang_err": SummaryColumn(
        "ang err\n/ tol °",
        "num",
        lambda r: err_of_tol(r.angle_err_median_deg, r.angle_tol_deg),
        "final tip angle error of the last leg, median over solved trials, beside the "
        "goal's angle tolerance [deg]",
    ),
    "checks": SummaryColumn(
        "checks\nmedian", "num", lambda r: fmt(r.checks_median), "collision checks, median"
    ),
    "minima": SummaryColumn(
        "minima\nmet/esc",
        "num",
        lambda r: f"{r.local_minima}/{r.escapes}",
        "local minima met / escaped, totals",
    ),
    "exec_ok": SummaryColumn(
        "executed\ncleanly",
        "num",
        _exec_ok,
        "executions in PyBullet that ran cleanly (no contact, clearance >= 0, deviation "
        "within max_deviation_m, goal reached), of those run",
        executed=True,
    ),
    "deviation": SummaryColumn(
        "deviation\nmm",
        "num",
        lambda r: fmt(mm(r.exec_deviation_median_m)),
        "largest deviation of the robot's collision geometry from the plan in "
        "PyBullet, median [mm]",
        executed=True,
    ),
    "clearance": SummaryColumn(
        "sim clear.\nmm",
        "num",
        lambda r: fmt(mm(r.exec_clearance_min_m)),
        "smallest simulated clearance (PyBullet's closest points) over the executions [mm]",
        executed=True,
    ),
    "track_err": SummaryColumn(
        "track\nerr rad",
        "num",
        lambda r: fmt(r.exec_track_err_median_rad),
        "largest joint tracking error in PyBullet, median [rad] (informational)",
        executed=True,
    ),
}
#: the default: fits 80 columns
COMPACT_COLUMNS = ("planner", "solved", "time", "checks", "minima", "exec_ok")
#: ``--wide``: everything the Markdown report shows
WIDE_COLUMNS = (
    "planner",
    "solved_n",
    "success",
    "time",
    "time_p75_p95",
    "path",
    "smoothness",
    "path_clearance",
    "pos_err",
    "ang_err",
    "checks",
    "minima",
    "exec_ok",
    "deviation",
    "clearance",
    "track_err",
)


def pick_columns(spec: str | None, wide: bool, executed: bool) -> list[str]:
    """The columns to show: ``--columns a,b`` (in that order), or the wide or compact set
    (without the execution columns when nothing was executed)."""
    if spec:
        keys = [k.strip() for k in spec.split(",") if k.strip()]
        for k in keys:
            if k not in SUMMARY_COLUMNS:
                raise UnknownNameError("column in --columns", k, SUMMARY_COLUMNS)
        return keys
    keys = list(WIDE_COLUMNS if wide else COMPACT_COLUMNS)
    return [k for k in keys if executed or not SUMMARY_COLUMNS[k].executed]


def summary_table(problem: str, rows: Sequence[Any], keys: Sequence[str]) -> Table:
    """``compare``'s table for one problem."""
    cols = [SUMMARY_COLUMNS[k] for k in keys]
    t = table(problem, [(c.header, c.kind) for c in cols], compact=True)
    for r in rows:
        cells = [Text(c.cell(r)) for c in cols]  # Text: never read as markup, on any console
        if "solved" in keys or "solved_n" in keys:
            i = keys.index("solved") if "solved" in keys else keys.index("solved_n")
            style = "green" if r.success_rate >= 0.95 else "red" if r.successes == 0 else "yellow"
            cells[i].stylize(style)
        t.add_row(*cells)
    return t


def natural_width(console: Console, renderable: Any) -> int:
    """Columns a renderable takes when nothing limits it."""
    return console.measure(renderable, options=console.options.update_width(10_000)).maximum


def fitted_groups(
    console: Console, keys: Sequence[str], build: Callable[[list[str]], Table]
) -> list[list[str]]:
    """``keys`` split into groups whose tables fit the console (the first key, the row's
    name, starts every group), so that no cell is cut: a wide table becomes two."""
    groups: list[list[str]] = []
    current = [keys[0]]
    for k in keys[1:]:
        trial = [*current, k]
        if len(current) == 1 or natural_width(console, build(trial)) <= console.width:
            current = trial
        else:
            groups.append(current)
            current = [keys[0], k]
    groups.append(current)
    return groups


def print_summary_tables(
    console: Console, problem: str, rows: Sequence[Any], keys: Sequence[str]
) -> None:
    """``compare``'s table(s) for one problem, split by columns where too wide."""
    for group in fitted_groups(console, keys, lambda ks: summary_table(problem, rows, ks)):
        console.print(summary_table(problem, rows, group))


def column_notes(keys: Sequence[str]) -> str:
    """One line per shown column: what it means."""
    return "; ".join(
        f"{' '.join(SUMMARY_COLUMNS[k].header.split())}: {SUMMARY_COLUMNS[k].help}" for k in keys
    )
