"""`plannerlab execute`: run a plan (or plan first) in PyBullet."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table
from rich.text import Text

from plannerlab import extras as px
from plannerlab.cli.common import require_display
from plannerlab.cli.solve import add_plan_arguments, into_folder, leg_table, solve_and_save
from plannerlab.cli.tables import Kind, natural_width, table
from plannerlab.errors import PlanFileError, PlannerlabError
from plannerlab.record.cells import fmt
from plannerlab.record.codec import dumps

#: columns the "why not" column gets at least (its phrases wrap at spaces)
WHY_MIN_WIDTH = 22


def why_table(legs: Any, executions: Any) -> Table:
    """Why each leg is not ok (the execution table's last column, on its own where the
    terminal is too narrow for both)."""
    t = table(
        "execution in PyBullet: why not ok",
        [("leg", "num"), ("goal", "name"), ("ok", "name"), ("why not", "text")],
        compact=True,
    )
    for r, e in zip(legs, executions, strict=True):
        ok = Text("yes", style="green") if e.success else Text("no", style="red")
        t.add_row(str(r.leg), str(r.goal), ok, "; ".join(e.failures))
    return t


def print_execution_tables(console: Console, legs: Any, executions: Any) -> None:
    """The execution table with its "why not" column, or, where the terminal has no
    room for that column, the table without it and :func:`why_table` under it."""
    narrow = execution_table(legs, executions, why=False)
    if natural_width(console, narrow) + WHY_MIN_WIDTH <= console.width:
        console.print(execution_table(legs, executions))
        return
    console.print(narrow)
    if not all(e.success for e in executions):
        console.print(why_table(legs, executions))


def execution_table(legs: Any, executions: Any, why: bool = True) -> Table:
    """One row per executed leg: FCL re-check, tip errors, the largest deviation of the
    robot's collision geometry from the plan and the smallest simulated
    clearance [mm], contacts, wall time, verdict and (``why``) why a leg is not ok (one
    phrase per failed test: :attr:`~plannerlab.record.execution.Execution.failures`);
    the joint tracking error, informational since the verdict is in metres, and the
    trajectory's duration are in ``--json``; which pairs collided or touched goes in the
    caption (names never cut)."""
    why_column: list[tuple[str, Kind]] = [("why not", "text")] if why else []
    t = table(
        "execution in PyBullet",
        [
            ("leg", "num"),
            ("goal", "name"),
            ("FCL", "name"),
            ("pos err\nm", "num"),
            ("ang err\n°", "num"),
            ("devia-\ntion mm", "num"),
            ("clear-\nance mm", "num"),
            ("con-\ntacts", "num"),
            ("wall s", "num"),
            ("ok", "name"),
            *why_column,
        ],
        compact=True,
    )
    if why:
        t.columns[-1].min_width = WHY_MIN_WIDTH
    notes = []
    for r, e in zip(legs, executions, strict=True):
        names = [f"{c.link_name} x {c.other_name}" for c in e.unexpected_contacts]
        if names:
            notes.append(f"leg {r.leg} {r.goal}: contacts " + ", ".join(names))
        if e.expected_contacts:
            planned = ", ".join(f"{c.link_name} x {c.other_name}" for c in e.expected_contacts)
            notes.append(f"leg {r.leg} {r.goal}: planned contacts {planned}")
        if e.path_valid is False:
            pairs = ", ".join(f"{a} x {b}" for a, b in e.recheck_pairs)
            notes.append(
                f"leg {r.leg} {r.goal}: FCL re-check collides on edge "
                f"{e.recheck_first_invalid_edge}: {pairs}"
            )
        verdict: str | Text = {True: "valid", None: "contact plan"}.get(e.path_valid, "")
        if e.path_valid is False:
            verdict = Text("collides", style="red")
        t.add_row(
            str(r.leg),
            str(r.goal),
            verdict,
            fmt(e.final_pos_err_m),
            fmt(e.final_angle_err_deg),
            fmt(1e3 * e.max_deviation_m),
            fmt(1e3 * e.min_clearance_m),
            str(len(names)),
            fmt(e.wall_time_s),
            Text("yes", style="green") if e.success else Text("no", style="red"),
            *(["; ".join(e.failures)] if why else []),
        )
    if notes:
        t.caption = "\n".join(notes)
    return t


def cmd_execute(args: argparse.Namespace, console: Console) -> int:
    import plannerlab as pl
    from plannerlab.record.files import versions
    from plannerlab.record.plan import ExecutionFile, execution_path

    require_display(args.gui)
    if args.problem.endswith(".json"):
        plan_file = Path(args.problem)
        plan = pl.read_plan(plan_file)
        changed = plan.problem_changed()
        if changed and plan.problem_path() is None:
            raise PlanFileError(f"{plan_file}: {changed}")
        if changed and not args.allow_changed_problem:
            raise PlanFileError(
                f"{plan_file}: {changed}; plan again, or pass --allow-changed-problem "
                "to execute the old plan on the new problem"
            )
        if changed:
            logging.getLogger(__name__).warning("%s: %s", plan_file, changed)
            if not args.json:
                console.print(Text.assemble(("warning:", "yellow"), f" {changed}"), soft_wrap=True)
    else:
        if not args.planner:
            raise PlannerlabError("execute PROBLEM needs --planner NAME (or give a PLAN.json)")
        plan, plan_file = solve_and_save(args, console)
    out = execution_path(plan_file)
    if args.out:
        out = into_folder(Path(args.out), out.name)
    problem = plan.load_problem()
    if args.problem.endswith(".json"):
        px.check_plan(plan, problem, args.problem)
    if not args.json:
        console.print(f"simulation: {problem.simulation.origin}", highlight=False)
    with console.status(f"executing {len(plan.legs)} legs in PyBullet"):
        executions = pl.execute(plan, problem, gui=args.gui)
    record = ExecutionFile.of(plan, plan_file, executions, versions())
    record.save(out)
    if args.json:
        print(dumps(record.to_dict()))
        return 1 if args.strict and not record.success else 0
    console.print(leg_table(plan, f"{plan.planner} on {plan.problem}, seed {plan.seed}: plan"))
    print_execution_tables(console, plan.legs, executions)
    console.print(f"execution written to {out} (plan: {plan_file})", soft_wrap=True)
    return 1 if args.strict and not all(e.success for e in executions) else 0


def add_parser(sub: Any) -> None:
    p = sub.add_parser("execute", help="plan (or load a plan) and execute it in PyBullet")
    add_plan_arguments(p, "execute")
    p.add_argument(
        "--allow-changed-problem",
        action="store_true",
        help="execute a plan even if its problem file changed since planning (warns)",
    )
    p.set_defaults(func=cmd_execute)
