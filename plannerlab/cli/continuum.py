"""``plannerlab continuum``: the continuum paper's table, figures and execution.

    plannerlab continuum CASE... [--runs 20] [--figures DIR] [--execute] [--out DIR]
                                 [--json] [--set KEY=VALUE]

``CASE`` is a problem name or path, or a bare number N for ``continuum_caseN``. For each
case the ``chord_arc`` planner is run ``--runs`` times (after one warm-up run) and the
table shows, beside the paper's numbers (``docs/papers.md`` §3: MATLAB 2019a,
i7-4790K): the median time of the search with its motion check (what the paper times),
the median time of the whole ``solve`` (plus the joint paths and the FCL contact
classification), collision points, solutions found, solutions dropped, and the chosen
one. A figure like the paper's Fig. 4 (obstacles, collision points, every solution,
target) is written per case to ``--figures`` (default ``results/``). ``--execute`` also
runs the chosen solution in PyBullet (the continuum executor) and shows the tip error
and the expected / unexpected contacts.

The data behind each row are the usual records: the first run is planned as
``plannerlab solve`` plans (seed 0), a plan whose one leg gives the row, and the
execution is an execution record. ``--out DIR`` writes them as any ``solve`` /
``execute`` would: ``DIR/<case>.plan.json`` and ``DIR/<case>.plan.exec.json`` (so
``plannerlab plot`` and ``plannerlab execute`` read them). The figures are drawn from
the legs' contact plans (the plane's obstacles, collision points, solutions): the first
run's and the zero-thickness run's, so a case costs ``--runs`` + 2 searches. ``--json``
prints one document (``planner``, ``runs``, ``overrides``, ``cases``: per case the timing
summary, the files written, and the ``plan`` and ``execution`` records).
"""

# Argument parsing, drawing and printing only: the runs are
# plannerlab.extras.run_continuum_case's (plannerlab/comparison/continuum.py). The
# docstring above is the command's help: no internal names.

from __future__ import annotations

import argparse
import contextlib
import os
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table
from rich.text import Text

from plannerlab import extras as px


def add_continuum_parser(subparsers: Any) -> argparse.ArgumentParser:
    """Register ``plannerlab continuum`` on the CLI's subparsers."""
    p = subparsers.add_parser(
        "continuum",
        help="the continuum paper's table and Fig. 4 (chord_arc planner)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "cases",
        nargs="+",
        metavar="CASE",
        help="problem name or .toml path, or N for continuum_caseN",
    )
    p.add_argument("--runs", type=int, default=20, help="timed runs per case (default 20)")
    p.add_argument(
        "--figures",
        default="results",
        metavar="DIR",
        help="folder for the Fig.-4-like PNGs (default results/)",
    )
    p.add_argument("--no-figures", action="store_true", help="draw nothing")
    p.add_argument("--execute", action="store_true", help="execute the chosen solution in PyBullet")
    p.add_argument(
        "--set",
        action="append",
        metavar="KEY=VALUE",
        help="override a chord_arc setting (repeatable)",
    )
    p.add_argument(
        "--out",
        metavar="DIR",
        help="write each case's plan to DIR/<case>.plan.json (and, with --execute, its "
        "execution to DIR/<case>.plan.exec.json), readable by plot and execute",
    )
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.set_defaults(func=cmd_continuum)
    return p


@contextlib.contextmanager
def _stdout_to_stderr(active: bool) -> Iterator[None]:
    """Send file descriptor 1 to stderr (PyBullet's C code prints ``argv[0]=`` on
    connecting), so that ``--json`` output stays pure JSON."""
    if not active:
        yield
        return
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def _thickness_figure(thin: Any, thick: Any, problem: Any, out: Path) -> Path:
    """Where the paper's zero-thickness curves and the robot of the problem's radius part,
    from the two legs' contact plans."""

    thin_plan, thick_plan = thin.contact_plan, thick.contact_plan
    r = problem.robot.link_radius_m
    kept = {s.contact_indices for s in thick_plan.searched}
    lost = [s.contact_indices for s in thin_plan.searched if s.contact_indices not in kept]
    title = (
        f"{problem.name}: {len(thin_plan.searched)} zero-thickness solution(s) (paper), "
        f"{len(thick_plan.searched)} for r = {r * 1e3:g} mm"
        + (f"; lost: {', '.join(str(list(c)) for c in lost)}" if lost else "")
    )
    fig = px.continuum_thickness_figure(thin_plan, thick_plan, title=title)
    return px.save_figure(fig, out / f"{problem.name}_thickness.png")


def _figure(problem: Any, result: Any, out: Path) -> Path:
    """Fig. 4: the search's curves, the planner's kept and dropped ones."""

    plan = result.contact_plan
    title = (
        f"{problem.name}: {len(plan.solutions)} solution(s), "
        f"{len(plan.collision_points_m)} collision points"
    )
    return px.continuum_case_figure(plan, out / f"{problem.name}.png", title=title)


def _write(row: Any, figures: Path | None, out: Path | None) -> dict[str, str]:
    """The case's figures (from its records' contact plans) and, with ``out``, its plan
    and execution files: what was written, by kind."""
    from plannerlab.record.files import versions
    from plannerlab.record.plan import ExecutionFile, execution_path

    problem, first = row.problem, row.result
    files: dict[str, str] = {}
    if figures is not None and first.contact_plan is not None and first.contact_plan.solutions:
        files["figure"] = str(_figure(problem, first, figures))
        if row.thin.contact_plan is not None and row.thick.contact_plan is not None:
            files["thickness_figure"] = str(
                _thickness_figure(row.thin, row.thick, problem, figures)
            )
    if out is not None:
        plan_file = row.plan.save(out / f"{problem.name}.plan.json")
        files["plan_file"] = str(plan_file)
        if row.execution is not None:
            record = ExecutionFile.of(row.plan, plan_file, [row.execution], versions())
            files["execution_file"] = str(record.save(execution_path(plan_file)))
    return files


def cmd_continuum(args: argparse.Namespace, console: Console) -> int:
    """``plannerlab continuum``: print the table (or JSON); write the figures and plans."""
    from plannerlab.cli.common import parse_overrides
    from plannerlab.errors import PlannerlabError
    from plannerlab.record.codec import dumps

    if args.runs < 1:
        raise PlannerlabError(f"--runs must be >= 1, got {args.runs}")
    overrides = parse_overrides(args.set)
    figures = None if args.no_figures else Path(args.figures)
    out = None if args.out is None else Path(args.out)
    for folder in (out, figures):  # a folder that cannot exist fails now, not after the runs
        if folder is not None:
            folder.mkdir(parents=True, exist_ok=True)
    rows: list[Any] = []
    written: list[dict[str, str]] = []
    with console.status("chord_arc") as status, _stdout_to_stderr(args.json):
        for case in args.cases:
            status.update(
                f"chord_arc on {px.continuum_case_name(case)}: {args.runs} runs"
                + (" and PyBullet" if args.execute else "")
            )
            rows.append(px.run_continuum_case(case, args.runs, overrides, execute=args.execute))
            written.append(_write(rows[-1], figures, out))
    if args.json:
        doc = {
            "planner": "chord_arc",
            "runs": args.runs,
            "overrides": overrides,
            "cases": [row.to_dict(files) for row, files in zip(rows, written, strict=True)],
        }
        print(dumps(doc))
        return 0
    t = Table(
        title=f"chord_arc on the continuum paper's cases (median of {args.runs} runs; "
        "paper: MATLAB 2019a, i7-4790K)",
        caption_justify="left",
    )
    cols = [
        "case",
        "status",
        "search ms",
        "solve ms",
        "paper ms",
        "points (paper)",
        "solutions (paper)",
        "zero-thickness",
        "dropped",
        "chosen: points",
        "same",
    ]
    if args.execute:
        cols += ["tip err mm", "expected", "unexpected"]
    for col in cols:
        t.add_column(col, justify="right", no_wrap=(col == "case"))
    notes = []
    for row, files in zip(rows, written, strict=True):
        r, timing = row.result, row.timing
        paper = timing["paper"]
        cp = r.contact_plan
        sol = cp.solutions if cp else ()
        chosen = cp.chosen if cp else None
        p_ms = f"{paper['time_s'] * 1e3:.0f}" if paper else "-"
        p_pts = f" ({paper['collision_points']})" if paper else ""
        p_sol = f" ({paper['solutions']})" if paper else ""
        style = "green" if r.status == "solved" else "red"
        cells = [
            r.problem.removeprefix("continuum_"),
            Text(r.status.value, style=style),
            f"{timing['search_median_s'] * 1e3:.2f}",
            f"{timing['solve_median_s'] * 1e3:.0f}",
            p_ms,
            f"{len(cp.collision_points_m) if cp else 0}{p_pts}",
            f"{len(sol)}{p_sol}",
            str(timing["solutions_zero_thickness"]),
            str(len(cp.dropped) if cp else 0),
            "-" if chosen is None else f"#{chosen}: {list(sol[chosen].contact_indices)}",
            "yes" if timing["same_every_run"] else Text("no", style="red"),
        ]
        if args.execute:
            e = row.execution
            if e is None:
                cells += ["-", "-", "-"]
            else:
                u = len(e.unexpected_contacts)
                cells += [
                    f"{e.final_pos_err_m * 1e3:.2f}",
                    str(len(e.expected_contacts)),
                    Text(str(u), style="red") if u else "0",
                ]
                notes.append(f"{r.problem} execution: {e.reason}")
        t.add_row(*cells)
        for d in cp.dropped if cp else ():
            notes.append(f"{r.problem} dropped: {d.reason}")
        if "figure" in files:
            notes.append(
                f"{r.problem} figures: "
                + ", ".join(files[k] for k in ("figure", "thickness_figure") if k in files)
            )
        if "plan_file" in files:
            notes.append(
                f"{r.problem} written: "
                + ", ".join(files[k] for k in ("plan_file", "execution_file") if k in files)
            )
    t.caption = "\n".join(
        [
            "search ms: search + contact-type check (what the paper times); solve ms: the "
            "planner's whole solve (joint paths, capsule contact classification); "
            "solutions: for the robot's radius (inflate_by_radius) unless set false; "
            "zero-thickness: the paper's model; same: every run gave the same status and "
            "counts; expected / unexpected: contact pairs in PyBullet"
        ]
        + notes
    )
    console.print(t)
    return 0


__all__ = ["add_continuum_parser", "cmd_continuum"]
