"""`plannerlab plot`: figures of a plan."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from rich.console import Console

from plannerlab import extras as px


def plan_executions(plan_file: str | Path) -> list[Any]:
    """The executions ``plannerlab execute PLAN.json`` wrote beside the plan
    (``PLAN.exec.json``), or none when it has not been executed."""
    from plannerlab.record.plan import ExecutionFile, execution_path

    path = execution_path(plan_file)
    return list(ExecutionFile.load(path).executions) if path.exists() else []


def cmd_plot(args: argparse.Namespace, console: Console) -> int:
    import plannerlab as pl

    plan, problem = px.read_checked_plan(args.plan)
    out_dir = Path(args.out) if args.out else Path(args.plan).with_suffix("")
    files = pl.plot_plan(plan, problem, out_dir, plan_executions(args.plan))
    if args.json:
        print(json.dumps([str(f) for f in files]))
    else:
        for f in files:
            console.print(f"wrote {f}", soft_wrap=True)
    return 0


def add_parser(sub: Any) -> None:
    p = sub.add_parser("plot", help="draw a plan: the arm at start, leg ends, stalls; f trace")
    p.add_argument("plan", help="PLAN.json written by solve/execute")
    p.add_argument("--out", help="folder for the PNG files (default: beside the plan)")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_plot)
