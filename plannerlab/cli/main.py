"""The ``plannerlab`` command: argument parsing and printing only.

plannerlab problems
plannerlab planners
plannerlab solve PROBLEM --planner NAME --seed N [--json] [--out PLAN.json]
plannerlab execute PROBLEM --planner NAME --seed N | plannerlab execute PLAN.json
plannerlab plot PLAN.json [--out DIR]
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.markup import escape
from rich.table import Table

from plannerlab.errors import PlannerlabError

RESULTS_DIR = Path("results")


def _fmt(x: Any, digits: int = 3) -> str:
    if x is None:
        return "-"
    if isinstance(x, float):
        if math.isnan(x):
            return "-"
        return f"{x:.{digits}g}" if abs(x) < 1e4 else f"{x:.0f}"
    return str(x)


def _parse_overrides(items: Sequence[str] | None) -> dict[str, str]:
    out: dict[str, str] = {}
    for item in items or []:
        if "=" not in item:
            raise PlannerlabError(f"--set expects KEY=VALUE, got {item!r}")
        k, v = item.split("=", 1)
        out[k.strip()] = v.strip()
    return out


def _budget_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--max-iterations", type=int, help="iteration budget per leg")
    p.add_argument("--max-checks", type=int, help="collision-check budget per leg")
    p.add_argument("--time-limit", type=float, help="time limit per leg [s]")


def _budget(problem: Any, args: argparse.Namespace) -> Any:
    return problem.budget.replace(
        max_iterations=args.max_iterations,
        max_collision_checks=args.max_checks,
        time_limit_s=args.time_limit,
    )


def _legs(problem: Any, spec: str | None) -> list[int] | None:
    if not spec or spec == "all":
        return None
    return [problem.resolve_leg(x.strip()) for x in spec.split(",")]


# ---------------------------------------------------------------------- commands
def cmd_problems(args: argparse.Namespace, console: Console) -> int:
    from plannerlab.problem.catalog import list_problems
    from plannerlab.problem.load import parse_problem

    rows = []
    for path in list_problems():
        p = parse_problem(path)
        rows.append(
            {
                "name": p.name,
                "file": str(path),
                "robot": p.robot.kind,
                "dof": p.robot.dof,
                "legs": [g.name for g in p.goals],
                "obstacles": len(p.scene.obstacles),
                "description": p.description,
            }
        )
    if args.json:
        print(json.dumps(rows, indent=1))
        return 0
    t = Table(title="problems")
    for col in ("name", "robot", "dof", "legs", "obstacles", "description"):
        t.add_column(col)
    for r in rows:
        t.add_row(
            r["name"],
            r["robot"],
            str(r["dof"]),
            ", ".join(r["legs"]),
            str(r["obstacles"]),
            r["description"],
        )
    console.print(t)
    return 0


def cmd_planners(args: argparse.Namespace, console: Console) -> int:
    from plannerlab.planners import REGISTRY

    rows = [
        {
            "name": e.name,
            "summary": e.summary,
            "needs_simulator": e.needs_stepper,
            "robots": list(e.robots) if e.robots else "any",
        }
        for e in REGISTRY.values()
    ]
    if args.json:
        print(json.dumps(rows, indent=1))
        return 0
    t = Table(title="planners")
    for col in ("name", "robots", "summary"):
        t.add_column(col)
    for r in rows:
        robots = r["robots"] if isinstance(r["robots"], str) else ", ".join(r["robots"])
        t.add_row(r["name"], robots, r["summary"])
    console.print(t)
    return 0


def _leg_table(plan: Any, title: str) -> Table:
    t = Table(title=title, caption_justify="left")
    for col in ("leg", "goal", "status", "iters", "time s", "checks", "pos err m", "ang err °"):
        t.add_column(col, no_wrap=(col == "status"))
    reasons = []
    for r in plan.legs:
        style = "green" if r.solved else ("yellow" if r.status == "local_minimum" else "red")
        t.add_row(
            str(r.leg),
            r.goal,
            f"[{style}]{r.status.value}[/{style}]",
            str(r.iterations),
            _fmt(r.time_s),
            str(r.collision_checks),
            _fmt(r.pos_err_m),
            _fmt(r.angle_err_deg),
        )
        reasons.append(f"{r.leg} {r.goal}: {r.reason}")
    t.caption = "\n".join(reasons)
    return t


def _default_plan_path(problem: str, planner: str, seed: int) -> Path:
    return RESULTS_DIR / "plans" / f"{problem}__{planner}__seed{seed}.json"


def _solve(args: argparse.Namespace, console: Console) -> Any:
    from plannerlab.bench.task import solve_legs
    from plannerlab.problem.catalog import load_problem

    problem = load_problem(args.problem)
    overrides = _parse_overrides(args.set)
    legs = _legs(problem, args.legs)
    n_legs = len(legs) if legs is not None else problem.legs
    status = console.status(f"{args.planner} on {problem.name}: leg 1/{n_legs}")

    done = []

    def on_leg(r: Any) -> None:
        done.append(r)
        status.update(
            f"{args.planner} on {problem.name}: leg {len(done) + 1}/{n_legs} "
            f"(last: {r.goal} {r.status.value})"
        )

    with status:
        plan = solve_legs(
            problem,
            args.planner,
            args.seed,
            legs=legs,
            budget=_budget(problem, args),
            overrides=overrides,
            gui=getattr(args, "gui", False),
            on_leg=on_leg,
        )
    out = Path(args.out) if args.out else _default_plan_path(problem.name, args.planner, args.seed)
    plan.save(out)
    return plan, out


def cmd_solve(args: argparse.Namespace, console: Console) -> int:
    plan, out = _solve(args, console)
    if args.json:
        print(json.dumps(plan.to_dict()))
    else:
        console.print(_leg_table(plan, f"{plan.planner} on {plan.problem}, seed {plan.seed}"))
        console.print(f"plan written to {out}")
    return 1 if args.strict and not plan.solved else 0


def cmd_execute(args: argparse.Namespace, console: Console) -> int:
    from dataclasses import replace

    from plannerlab.bench.task import Plan
    from plannerlab.sim.execute import execute_legs

    if args.problem.endswith(".json"):
        out = Path(args.problem)
        plan = Plan.load(out)
    else:
        if not args.planner:
            raise PlannerlabError("execute PROBLEM needs --planner NAME (or give a PLAN.json)")
        plan, out = _solve(args, console)
    problem = plan.load_problem()
    with console.status(f"executing {len(plan.legs)} legs in PyBullet"):
        executions = execute_legs(
            problem, [r.path for r in plan.legs], first_leg=plan.legs[0].leg, gui=args.gui
        )
    plan = replace(plan, executions=tuple(e.to_dict() for e in executions))
    plan.save(out)
    if args.json:
        print(json.dumps(plan.to_dict()))
        return 1 if args.strict and not all(e.success for e in executions) else 0
    console.print(_leg_table(plan, f"{plan.planner} on {plan.problem}, seed {plan.seed}: plan"))
    t = Table(title="execution in PyBullet")
    for col in (
        "leg",
        "goal",
        "FCL re-check",
        "pos err m",
        "ang err °",
        "max track err rad",
        "contacts",
        "sim s",
        "wall s",
        "ok",
    ):
        t.add_column(col, overflow="fold")
    for r, e in zip(plan.legs, executions, strict=True):
        names = [f"{c.link_name} x {c.other_name}" for c in e.contacts]
        contacts = ", ".join(names[:2]) + (f" +{len(names) - 2} more" if len(names) > 2 else "")
        contacts = contacts or "none"
        recheck = (
            "valid"
            if e.path_valid
            else f"collides on edge {e.recheck_first_invalid_edge}: "
            + ", ".join(f"{a} x {b}" for a, b in e.recheck_pairs)
        )
        t.add_row(
            str(r.leg),
            r.goal,
            recheck,
            _fmt(e.final_pos_err_m),
            _fmt(e.final_angle_err_deg),
            _fmt(e.max_track_err_rad),
            contacts,
            _fmt(e.sim_time_s),
            _fmt(e.wall_time_s),
            "[green]yes[/green]" if e.success else "[red]no[/red]",
        )
    console.print(t)
    console.print(f"plan and execution written to {out}")
    return 1 if args.strict and not all(e.success for e in executions) else 0


def cmd_plot(args: argparse.Namespace, console: Console) -> int:
    from plannerlab.bench.task import Plan
    from plannerlab.plot.plans import plot_plan

    plan = Plan.load(args.plan)
    out_dir = Path(args.out) if args.out else Path(args.plan).with_suffix("")
    files = plot_plan(plan, plan.load_problem(), out_dir)
    if args.json:
        print(json.dumps([str(f) for f in files]))
    else:
        for f in files:
            console.print(f"wrote {f}")
    return 0


# ---------------------------------------------------------------------- parser
def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="plannerlab", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log at INFO level")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("problems", help="list the bundled problems")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_problems)

    p = sub.add_parser("planners", help="list the registered planners")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_planners)

    for name, func, helptext in (
        ("solve", cmd_solve, "plan every leg of a problem and print a table per leg"),
        ("execute", cmd_execute, "plan (or load a plan) and execute it in PyBullet"),
    ):
        p = sub.add_parser(name, help=helptext)
        p.add_argument(
            "problem",
            help="problem name or .toml path" + (" (or a PLAN.json)" if name == "execute" else ""),
        )
        p.add_argument("--planner", required=(name == "solve"), help="registry name")
        p.add_argument("--seed", type=int, default=0)
        p.add_argument("--legs", help="comma-separated leg names or indices (default: all)")
        p.add_argument(
            "--set",
            action="append",
            metavar="KEY=VALUE",
            help="override a planner setting (repeatable)",
        )
        p.add_argument("--out", help="plan file to write (default results/plans/...)")
        p.add_argument("--json", action="store_true", help="machine-readable output")
        p.add_argument("--gui", action="store_true", help="PyBullet window instead of DIRECT")
        p.add_argument(
            "--strict",
            action="store_true",
            help="exit 1 unless every leg is solved (and executed cleanly)",
        )
        _budget_args(p)
        p.set_defaults(func=func)

    p = sub.add_parser("plot", help="draw a plan: the arm at start, leg ends, stalls; f trace")
    p.add_argument("plan", help="PLAN.json written by solve/execute")
    p.add_argument("--out", help="folder for the PNG files (default: beside the plan)")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_plot)
    from plannerlab.cli.ik import add_ik_parser

    add_ik_parser(sub)
    from plannerlab.cli.compare import add_compare_parser

    add_compare_parser(sub)
    from plannerlab.cli.continuum import add_continuum_parser

    add_continuum_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    to_stderr = bool(getattr(args, "json", False))
    stream = sys.stderr if to_stderr else sys.stdout
    # In a log or a pipe rich would wrap at 80 columns: tables read better wider.
    console = Console(stderr=to_stderr, width=None if stream.isatty() else 150)
    try:
        return int(args.func(args, console) or 0)
    except PlannerlabError as exc:
        # escape: messages name keys in brackets ("[goals[0].n]"), which rich would eat
        Console(stderr=True).print(f"[red]error:[/red] {escape(str(exc))}", highlight=False)
        return 2
    except KeyboardInterrupt:
        Console(stderr=True).print("interrupted")
        return 130


if __name__ == "__main__":
    sys.exit(main())
