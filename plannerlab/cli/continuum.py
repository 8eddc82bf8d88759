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
runs the chosen solution in PyBullet (:func:`plannerlab.sim.continuum.execute_chord_arc`)
and shows the tip error and the expected / unexpected contacts.

The data behind each row are the house's records: the first run is planned by
:func:`plannerlab.run.pipeline.solve_legs` (seed 0) into a :class:`~plannerlab.record.plan.Plan`
whose one :class:`~plannerlab.record.leg.PlanResult` gives the row, and the execution is
an :class:`~plannerlab.record.execution.Execution`. ``--out DIR`` writes them as any
``solve`` / ``execute`` would: ``DIR/<case>.plan.json`` and ``DIR/<case>.plan.exec.json``
(so ``plannerlab plot`` and ``plannerlab execute`` read them). The figures are drawn from
the legs' contact plans (:class:`~plannerlab.record.contact_plan.ContactPlan`): the first
run's and the zero-thickness run's, so a case costs ``--runs`` + 2 searches. ``--json`` prints one
document (``planner``, ``runs``, ``overrides``, ``cases``: per case the timing summary,
the files written, and the ``plan`` and ``execution`` records through the one codec).

Argument parsing and printing only; the work is done by the library.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import os
import statistics
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.markup import escape
from rich.table import Table


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


def _case_name(case: str) -> str:
    return f"continuum_case{case}" if case.isdigit() else case


def _thickness_figure(thin: Any, thick: Any, problem: Any, out: Path) -> Path:
    """Where the paper's zero-thickness curves and the robot of the problem's radius part,
    from the two legs' contact plans."""
    from plannerlab.plot.continuum import save, searched, thickness_figure

    thin_plan, thick_plan = thin.contact_plan, thick.contact_plan
    r = problem.robot.link_radius_m
    kept = {s.contact_indices for s in searched(thick_plan)}
    lost = [s.contact_indices for s in searched(thin_plan) if s.contact_indices not in kept]
    title = (
        f"{problem.name}: {len(searched(thin_plan))} zero-thickness solution(s) (paper), "
        f"{len(searched(thick_plan))} for r = {r * 1e3:g} mm"
        + (f"; lost: {', '.join(str(list(c)) for c in lost)}" if lost else "")
    )
    fig = thickness_figure(thin_plan, thick_plan, title=title)
    return save(fig, out / f"{problem.name}_thickness.png")


def _figure(problem: Any, result: Any, out: Path) -> Path:
    """Fig. 4: the search's curves, the planner's kept and dropped ones."""
    from plannerlab.plot.continuum import draw_case

    plan = result.contact_plan
    title = (
        f"{problem.name}: {len(plan.solutions)} solution(s), "
        f"{len(plan.collision_points_m)} collision points"
    )
    return draw_case(plan, out / f"{problem.name}.png", title=title)


@dataclasses.dataclass(frozen=True)
class CaseRun:
    """One case of the table: the records behind its row and the timing summary.

    Attributes:
        plan: the first (warm-up) run as a plan (:func:`plannerlab.run.pipeline.solve_legs`,
            seed 0): its one leg's :class:`~plannerlab.record.leg.PlanResult` is the row.
        execution: the chosen solution executed in PyBullet (``--execute``), or None.
        timing: ``runs``, ``search_median_s``, ``solve_median_s``, ``same_every_run``,
            ``solutions_zero_thickness`` and the paper's row (``paper``, or None).
        files: what was written: ``figure``, ``thickness_figure``, ``plan_file``,
            ``execution_file``.
    """

    plan: Any
    execution: Any
    timing: dict[str, Any]
    files: dict[str, str]

    @property
    def result(self) -> Any:
        return self.plan.legs[0]

    def to_dict(self) -> dict[str, Any]:
        """The case as data: the records through their own ``to_dict`` (the codec's)."""
        return {
            "problem": self.plan.problem,
            **self.timing,
            "files": self.files,
            "plan": self.plan.to_dict(),
            "execution": None if self.execution is None else self.execution.to_dict(),
        }


def run_case(
    case: str,
    runs: int,
    overrides: dict[str, Any],
    figures: Path | None,
    do_execute: bool,
    out: Path | None = None,
) -> CaseRun:
    """One row of the table: the plan record, the timed runs, the execution record."""
    from plannerlab.planners import make_planner
    from plannerlab.planners.chord_arc.planner import PAPER_TABLE
    from plannerlab.planners.chord_arc.scene import guide_obstacles
    from plannerlab.problem.catalog import load_problem
    from plannerlab.record.files import versions
    from plannerlab.record.plan import ExecutionFile, execution_path
    from plannerlab.run.pipeline import execute_results, leg_rng, solve_legs

    problem = load_problem(_case_name(case))
    planner = make_planner("chord_arc", overrides)
    budget = problem.budget
    plan = solve_legs(problem, "chord_arc", 0, legs=[0], overrides=overrides)  # warm-up
    first = plan.legs[0]
    solve_s, search_s, counts = [], [], set()
    for i in range(runs):
        r = planner.solve(problem, 0, budget, leg_rng(i, 0))
        solve_s.append(r.time_s)
        cp = r.contact_plan
        search_s.append(float(cp.search.get("time_s", float("nan"))) if cp else float("nan"))
        counts.add((r.status.value, *((len(cp.solutions), len(cp.dropped)) if cp else ())))
    paper = PAPER_TABLE.get(problem.name)
    thin = make_planner("chord_arc", {**overrides, "inflate_by_radius": False})
    thin_r = thin.solve(problem, 0, budget, leg_rng(0, 0))
    timing: dict[str, Any] = {
        "runs": runs,
        "search_median_s": statistics.median(search_s),
        "solve_median_s": statistics.median(solve_s),
        "same_every_run": len(counts) <= 1,
        "solutions_zero_thickness": (
            len(thin_r.contact_plan.solutions) if thin_r.contact_plan else 0
        ),
        "paper": None if paper is None else dataclasses.asdict(paper),
    }
    files: dict[str, str] = {}
    first_plan = first.contact_plan
    if figures is not None and first_plan is not None and first_plan.solutions:
        files["figure"] = str(_figure(problem, first, figures))
        thick = first
        if not first.settings.get("inflate_by_radius", True):
            thick_planner = make_planner("chord_arc", {**overrides, "inflate_by_radius": True})
            thick = thick_planner.solve(problem, 0, budget, leg_rng(0, 0))
        if thin_r.contact_plan is not None and thick.contact_plan is not None:
            files["thickness_figure"] = str(_thickness_figure(thin_r, thick, problem, figures))
    execution = None
    if do_execute and first_plan is not None and first_plan.chosen is not None:
        guide_obstacles(problem)  # validated (the plan's extra carries the names)
        (execution,) = execute_results(problem, plan.legs)
    if out is not None:
        plan_file = plan.save(out / f"{problem.name}.plan.json")
        files["plan_file"] = str(plan_file)
        if execution is not None:
            record = ExecutionFile.of(plan, plan_file, [execution], versions())
            files["execution_file"] = str(record.save(execution_path(plan_file)))
    return CaseRun(plan, execution, timing, files)


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
    rows: list[CaseRun] = []
    with console.status("chord_arc") as status, _stdout_to_stderr(args.json):
        for case in args.cases:
            status.update(
                f"chord_arc on {_case_name(case)}: {args.runs} runs"
                + (" and PyBullet" if args.execute else "")
            )
            rows.append(run_case(case, args.runs, overrides, figures, args.execute, out))
    if args.json:
        doc = {
            "planner": "chord_arc",
            "runs": args.runs,
            "overrides": overrides,
            "cases": [row.to_dict() for row in rows],
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
        t.add_column(escape(col), justify="right", no_wrap=(col == "case"))
    notes = []
    for row in rows:
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
            f"[{style}]{r.status.value}[/{style}]",
            f"{timing['search_median_s'] * 1e3:.2f}",
            f"{timing['solve_median_s'] * 1e3:.0f}",
            p_ms,
            f"{len(cp.collision_points_m) if cp else 0}{p_pts}",
            f"{len(sol)}{p_sol}",
            str(timing["solutions_zero_thickness"]),
            str(len(cp.dropped) if cp else 0),
            "-" if chosen is None else f"#{chosen}: {list(sol[chosen].contact_indices)}",
            "yes" if timing["same_every_run"] else "[red]no[/red]",
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
                    f"[red]{u}[/red]" if u else "0",
                ]
                notes.append(f"{r.problem} execution: {e.reason}")
        t.add_row(*cells)
        for d in cp.dropped if cp else ():
            notes.append(f"{r.problem} dropped: {d.reason}")
        if "figure" in row.files:
            notes.append(
                f"{r.problem} figures: {row.files['figure']}, {row.files['thickness_figure']}"
            )
        if "plan_file" in row.files:
            written = row.files["plan_file"]
            if "execution_file" in row.files:
                written += f", {row.files['execution_file']}"
            notes.append(f"{r.problem} written: {written}")
    t.caption = escape(
        "\n".join(
            [
                "search ms: search + contact-type check (what the paper times); solve ms: the "
                "planner's whole solve (joint paths, capsule contact classification); "
                "solutions: for the robot's radius (inflate_by_radius) unless set false; "
                "zero-thickness: the paper's model; same: every run gave the same status and "
                "counts; expected / unexpected: contact pairs in PyBullet"
            ]
            + notes
        )
    )
    console.print(t)
    return 0


__all__ = ["CaseRun", "add_continuum_parser", "cmd_continuum", "run_case"]
