"""`plannerlab planners [NAME]`: the registered planners and what each suits; one
planner's settings with units, defaults and what each does."""

from __future__ import annotations

import argparse
import json
from typing import Any

from rich.console import Console
from rich.text import Text

from plannerlab.cli.tables import table


def _default(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:g}"
    return str(value)


def _show_planner(console: Console, info: dict[str, Any]) -> None:
    robots = info["robots"] if isinstance(info["robots"], str) else ", ".join(info["robots"])
    seeds = "draws from its seed" if info["uses_rng"] else "deterministic: the seed changes nothing"
    console.print(Text.assemble((info["name"], "bold"), f": {info['summary']}"))
    console.print(f"suits: {info['suits'] or '-'} (robot kinds: {robots})")
    console.print(
        f"{seeds}" + ("; runs PyBullet in its loop" if info["needs_simulator"] else ""),
        highlight=False,
    )
    t = table(
        "settings (override with --set key=value)",
        [("key", "name"), ("default", "num"), ("unit", "name"), ("what it does", "text")],
        compact=True,
    )
    for s in info["settings"]:
        t.add_row(s["key"], _default(s["default"]), s["unit"], s["doc"])
    console.print(t)


def cmd_planners(args: argparse.Namespace, console: Console) -> int:
    import plannerlab as pl

    if args.name:
        info = pl.planner_info(args.name)
        if args.json:
            print(json.dumps(info, indent=1))
        else:
            _show_planner(console, info)
        return 0
    rows = pl.planner_catalog()
    if args.json:
        print(json.dumps(rows, indent=1))
        return 0
    t = table("planners", [("name", "name"), ("suits", "text"), ("summary", "text")])
    for r in rows:
        only = "" if isinstance(r["robots"], str) else f" ({', '.join(r['robots'])} only)"
        seeds = "" if r["uses_rng"] else " (deterministic: the seed changes nothing)"
        t.add_row(r["name"], r["suits"] + only, r["summary"] + seeds)
    console.print(t)
    console.print("a planner's settings: plannerlab planners NAME", highlight=False)
    return 0


def add_parser(sub: Any) -> None:
    p = sub.add_parser(
        "planners",
        help="list the registered planners and what each suits; NAME: its settings",
    )
    p.add_argument(
        "name",
        nargs="?",
        metavar="NAME",
        help="a planner: its settings with units, defaults and what each does",
    )
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.set_defaults(func=cmd_planners)
