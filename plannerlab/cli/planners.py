"""`plannerlab planners`: the registered planners."""

from __future__ import annotations

import argparse
import json
from typing import Any

from rich.console import Console

from plannerlab.cli.tables import table


def cmd_planners(args: argparse.Namespace, console: Console) -> int:
    import plannerlab as pl

    rows = pl.planner_catalog()
    if args.json:
        print(json.dumps(rows, indent=1))
        return 0
    t = table("planners", [("name", "name"), ("robots", "text"), ("summary", "text")])
    for r in rows:
        robots = r["robots"] if isinstance(r["robots"], str) else ", ".join(r["robots"])
        seeds = "" if r["uses_rng"] else " (deterministic: the seed changes nothing)"
        t.add_row(r["name"], robots, r["summary"] + seeds)
    console.print(t)
    return 0


def add_parser(sub: Any) -> None:
    p = sub.add_parser("planners", help="list the registered planners")
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.set_defaults(func=cmd_planners)
