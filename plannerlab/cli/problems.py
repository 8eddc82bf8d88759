"""`plannerlab problems`: the bundled problems."""

from __future__ import annotations

import argparse
import json
from typing import Any

from rich.console import Console
from rich.table import Table


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


def add_parser(sub: Any) -> None:
    p = sub.add_parser("problems", help="list the bundled problems")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.set_defaults(func=cmd_problems)
