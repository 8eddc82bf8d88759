"""``plannerlab continuum``: the continuum paper's table, figures and execution.

    plannerlab continuum CASE... [--runs 20] [--figures DIR] [--execute] [--json]
                                 [--set KEY=VALUE]

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

Argument parsing and printing only; the work is done by the library.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import json
import os
import statistics
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
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


def _thickness_figure(planner: Any, problem: Any, out: Path) -> Path:
    """Where the paper's zero-thickness curves and the robot of the problem's radius part."""
    from plannerlab.planners.chord_arc import thickness_cuts
    from plannerlab.plot.continuum import save, thickness_figure

    thin_planner = planner.with_settings(inflate_by_radius=False)
    thick_planner = planner.with_settings(inflate_by_radius=True)
    query, thin = thin_planner.search(problem, 0)
    grown = thick_planner.planning_query(problem, query)
    _, thick = thick_planner.search(problem, 0)
    r = problem.robot.link_radius_m
    cuts = [thickness_cuts(query, p.solution, r) for p in thin.plans]
    kept = {p.solution.contact_indices for p in thick.plans}
    lost = [
        p.solution.contact_indices for p in thin.plans if p.solution.contact_indices not in kept
    ]
    title = (
        f"{problem.name}: {len(thin.plans)} zero-thickness solution(s) (paper), "
        f"{len(thick.plans)} for r = {r * 1e3:g} mm"
        + (f"; lost: {', '.join(str(list(c)) for c in lost)}" if lost else "")
    )
    fig = thickness_figure(
        query,
        grown,
        [p.solution for p in thin.plans],
        [p.solution for p in thick.plans],
        r,
        np.vstack(cuts) if cuts else np.zeros((0, 2)),
        title=title,
    )
    return save(fig, out / f"{problem.name}_thickness.png")


def _figure(planner: Any, problem: Any, result: Any, out: Path) -> Path:
    """Fig. 4: the search's curves, split into the planner's kept and dropped ones."""
    from plannerlab.planners.chord_arc_search import ChordArcResult, DroppedSolution
    from plannerlab.plot.continuum import draw_case

    query, res = planner.search(problem, result.leg)
    kept = {tuple(s["contact_indices"]) for s in result.extra["solutions"]}
    plans = tuple(p for p in res.plans if p.solution.contact_indices in kept)
    chain_dropped = tuple(
        DroppedSolution(p.solution, p.contacts, "dropped by the chain check")
        for p in res.plans
        if p.solution.contact_indices not in kept
    )
    shown = ChordArcResult(res.search, plans, res.dropped + chain_dropped)
    title = (
        f"{problem.name}: {len(plans)} solution(s), "
        f"{len(query.collision_points_m)} collision points"
    )
    return draw_case(query, shown, out / f"{problem.name}.png", title=title)


def run_case(
    case: str, runs: int, overrides: dict[str, Any], figures: Path | None, do_execute: bool
) -> dict[str, Any]:
    """One row of the table as data (JSON-able)."""
    from plannerlab.bench.task import leg_rng
    from plannerlab.planners import make_planner
    from plannerlab.planners.chord_arc import PAPER_TABLE, guide_obstacles
    from plannerlab.problem.catalog import load_problem

    problem = load_problem(_case_name(case))
    planner = make_planner("chord_arc", overrides)
    budget = problem.budget
    first = planner.solve(problem, 0, budget, leg_rng(0, 0))  # warm-up, and the result
    solve_s, search_s, counts = [], [], set()
    for i in range(runs):
        r = planner.solve(problem, 0, budget, leg_rng(i, 0))
        solve_s.append(r.time_s)
        search_s.append(r.extra.get("search", {}).get("time_s", float("nan")))
        counts.add((r.status.value, len(r.extra["solutions"]), len(r.extra["dropped"])))
    paper = PAPER_TABLE.get(problem.name)
    thin = make_planner("chord_arc", {**overrides, "inflate_by_radius": False})
    thin_r = thin.solve(problem, 0, budget, leg_rng(0, 0))
    sol = first.extra["solutions"]
    chosen = first.extra["chosen"]
    row: dict[str, Any] = {
        "problem": problem.name,
        "status": first.status.value,
        "reason": first.reason,
        "runs": runs,
        "search_median_s": statistics.median(search_s) if runs else None,
        "solve_median_s": statistics.median(solve_s) if runs else None,
        "collision_points": len(first.extra["collision_points_m"]),
        "solutions": len(sol),
        "inflated": bool(first.settings.get("inflate_by_radius")),
        "solutions_zero_thickness": len(thin_r.extra["solutions"]),
        "dropped": len(first.extra["dropped"]),
        "dropped_reasons": [d["reason"] for d in first.extra["dropped"]],
        "chosen": chosen,
        "chosen_contacts": sol[chosen]["contact_indices"] if chosen is not None else None,
        "expansions": first.iterations,
        "same_every_run": len(counts) <= 1,
        "paper": None if paper is None else dataclasses.asdict(paper),
        "solutions_data": sol,
        "settings": dict(first.settings),
    }
    if figures is not None and sol:
        row["figure"] = str(_figure(planner, problem, first, figures))
        row["thickness_figure"] = str(_thickness_figure(planner, problem, figures))
    if do_execute and first.extra.get("chosen") is not None:
        from plannerlab.sim.continuum import execute_chord_arc

        guide_obstacles(problem)  # validated (the plan's extra carries the names)
        row["execution"] = execute_chord_arc(
            problem, first.path, first.extra, leg=first.leg
        ).to_dict()
    return row


def cmd_continuum(args: argparse.Namespace, console: Console) -> int:
    """``plannerlab continuum``: print the table (or JSON); write the figures."""
    from plannerlab.cli.common import parse_overrides
    from plannerlab.errors import PlannerlabError

    if args.runs < 1:
        raise PlannerlabError(f"--runs must be >= 1, got {args.runs}")
    overrides = parse_overrides(args.set)
    figures = None if args.no_figures else Path(args.figures)
    rows = []
    with console.status("chord_arc") as status, _stdout_to_stderr(args.json):
        for case in args.cases:
            status.update(
                f"chord_arc on {_case_name(case)}: {args.runs} runs"
                + (" and PyBullet" if args.execute else "")
            )
            rows.append(run_case(case, args.runs, overrides, figures, args.execute))
    if args.json:
        print(json.dumps(rows))
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
    for r in rows:
        paper = r["paper"]
        p_ms = f"{paper['time_s'] * 1e3:.0f}" if paper else "-"
        p_pts = f" ({paper['collision_points']})" if paper else ""
        p_sol = f" ({paper['solutions']})" if paper else ""
        style = "green" if r["status"] == "solved" else "red"
        cells = [
            r["problem"].removeprefix("continuum_"),
            f"[{style}]{r['status']}[/{style}]",
            f"{r['search_median_s'] * 1e3:.2f}",
            f"{r['solve_median_s'] * 1e3:.0f}",
            p_ms,
            f"{r['collision_points']}{p_pts}",
            f"{r['solutions']}{p_sol}",
            str(r["solutions_zero_thickness"]),
            str(r["dropped"]),
            "-" if r["chosen"] is None else f"#{r['chosen']}: {r['chosen_contacts']}",
            "yes" if r["same_every_run"] else "[red]no[/red]",
        ]
        if args.execute:
            e = r.get("execution")
            if e is None:
                cells += ["-", "-", "-"]
            else:
                u = e["unexpected"]
                cells += [
                    f"{e['tip_error_m'] * 1e3:.2f}",
                    str(e["expected"]),
                    f"[red]{u}[/red]" if u else "0",
                ]
                notes.append(f"{r['problem']} execution: {e['reason']}")
        t.add_row(*cells)
        for d in r["dropped_reasons"]:
            notes.append(f"{r['problem']} dropped: {d}")
        if "figure" in r:
            notes.append(f"{r['problem']} figures: {r['figure']}, {r['thickness_figure']}")
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


__all__ = ["add_continuum_parser", "cmd_continuum", "run_case"]
