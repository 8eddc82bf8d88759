"""`plannerlab solve`: plan every leg of a problem and write a plan file."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.table import Table
from rich.text import Text

from plannerlab import extras as px
from plannerlab.cli.common import (
    RESULTS_DIR,
    add_budget_args,
    budget_from_args,
    leg_spec,
    parse_overrides,
    require_display,
    seed_int,
)
from plannerlab.cli.tables import path_note, table, tip_error_cells
from plannerlab.record.cells import fmt
from plannerlab.record.codec import dumps


def leg_table(plan: Any, title: str) -> Table:
    t = table(
        title,
        [
            ("leg", "num"),
            ("goal", "name"),
            ("status", "name"),
            ("iters", "num"),
            ("time s", "num"),
            ("checks", "num"),
            ("pos err\n/ tol m", "num"),
            ("ang err\n/ tol °", "num"),
        ],
        compact=True,
    )
    reasons = []
    for r in plan.legs:
        style = "green" if r.solved else ("yellow" if r.status == "local_minimum" else "red")
        t.add_row(
            str(r.leg),
            r.goal,
            Text(r.status.value, style=style),
            str(r.iterations),
            fmt(r.time_s),
            str(r.collision_checks),
            *tip_error_cells(r),  # beside the tolerance; "—" for a leg with no result
        )
        reasons.append(f"{r.leg} {r.goal}: {r.reason}{path_note(r)}")
    t.caption = "\n".join(reasons)
    return t


def into_folder(out: Path, name: str) -> Path:
    """``--out``: a file to write, or an existing folder to write ``name`` into (checked
    before any work, so a plan is never computed and then lost at saving)."""
    return out / name if out.is_dir() else out


def _default_plan_path(problem: str, planner: str, seed: int) -> Path:
    return RESULTS_DIR / "plans" / f"{problem}__{planner}__seed{seed}.json"


def solve_and_save(args: argparse.Namespace, console: Console, out: Path | None = None) -> Any:
    """Solve as the flags say and write the plan file (``out``, default beside the
    results); return the plan and where it went."""
    import plannerlab as pl

    problem = pl.load_problem(args.problem)
    if not getattr(args, "json", False):
        console.print(
            f"problem {problem.name} from {problem.source}", highlight=False, soft_wrap=True
        )
    overrides = parse_overrides(args.set)
    legs = px.legs_from_spec(problem, args.legs)
    n_legs = len(legs) if legs is not None else problem.legs
    default = _default_plan_path(problem.name, args.planner, args.seed)
    out = into_folder(out, default.name) if out else default
    out.parent.mkdir(parents=True, exist_ok=True)  # a path that cannot exist fails now
    status = console.status(f"{args.planner} on {problem.name}: leg 1/{n_legs}")

    done = []

    def on_leg(r: Any) -> None:
        done.append(r)
        status.update(
            f"{args.planner} on {problem.name}: leg {len(done) + 1}/{n_legs} "
            f"(last: {r.goal} {r.status.value})"
        )

    with status:
        plan = pl.solve(
            problem,
            args.planner,
            args.seed,
            legs=legs,
            budget=budget_from_args(problem, args),
            overrides=overrides,
            gui=getattr(args, "gui", False),
            on_leg=on_leg,
        )
    plan.save(out)
    return plan, out


def cmd_solve(args: argparse.Namespace, console: Console) -> int:
    require_display(args.gui)
    plan, out = solve_and_save(args, console, Path(args.out) if args.out else None)
    if args.json:
        print(dumps(plan.to_dict(out)))
    else:
        console.print(leg_table(plan, f"{plan.planner} on {plan.problem}, seed {plan.seed}"))
        console.print(f"plan written to {out}", soft_wrap=True)
    return 1 if args.strict and not plan.solved else 0


def add_plan_arguments(p: argparse.ArgumentParser, name: str) -> None:
    """The arguments `solve` and `execute` share."""
    p.add_argument(
        "problem",
        help="problem: a .toml path, or a name looked up in ./problems, then among the "
        "bundled problems" + (" (or a PLAN.json written by solve)" if name == "execute" else ""),
    )
    p.add_argument(
        "--planner",
        required=(name == "solve"),
        help="planner name, as listed by 'plannerlab planners'",
    )
    p.add_argument(
        "--seed",
        type=seed_int,
        default=0,
        help="random seed (>= 0); the same seed gives the same plan",
    )
    p.add_argument(
        "--legs",
        type=leg_spec,
        help="comma-separated leg names or indices, or 'all' (default: all)",
    )
    p.add_argument(
        "--set",
        action="append",
        metavar="KEY=VALUE",
        help="override a planner setting (repeatable)",
    )
    p.add_argument(
        "--out",
        help=(
            "plan file to write (default results/plans/PROBLEM__PLANNER__seedN.json)"
            if name == "solve"
            else "execution file to write (default: PLAN.exec.json beside the plan; "
            "a plan made here goes to results/plans/)"
        ),
    )
    p.add_argument("--json", action="store_true", help="machine-readable output")
    p.add_argument(
        "--gui", action="store_true", help="PyBullet window instead of DIRECT (needs a display)"
    )
    p.add_argument(
        "--strict",
        action="store_true",
        help="exit 1 unless every leg is solved (and executed cleanly)",
    )
    add_budget_args(p)


def add_parser(sub: Any) -> None:
    p = sub.add_parser("solve", help="plan every leg of a problem and print a table per leg")
    add_plan_arguments(p, "solve")
    p.set_defaults(func=cmd_solve)
