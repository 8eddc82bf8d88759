"""`plannerlab problems`: the problems a name resolves to (``./problems`` first, then the
bundled ones)."""

from __future__ import annotations

import argparse
import json
from typing import Any

from rich.console import Console
from rich.text import Text

from plannerlab.cli.tables import Kind, table

#: console width from which descriptions get a column
WIDE = 120


def cmd_problems(args: argparse.Namespace, console: Console) -> int:
    import plannerlab as pl
    from plannerlab.errors import PlannerlabError

    rows: list[dict[str, Any]] = []
    for name, path, origin, group in pl.problem_catalog():
        # the name it loads by: its stem, or its sub-folder and stem when the stem is shared
        row: dict[str, Any] = {"name": name, "file": str(path), "from": origin}
        row["group"] = group
        try:
            p = pl.parse_problem(path)
        except PlannerlabError as exc:  # a broken local file is listed with its error
            row.update(error=str(exc), robot="-", dof=None, legs=[], obstacles=None)
            row["description"] = f"error: {exc}"
            rows.append(row)
            continue
        row.update(
            problem_name=p.name,  # its [problem] name; the command line uses "name"
            robot=p.robot.kind,
            dof=p.robot.dof,
            legs=[g.name for g in p.goals],
            obstacles=len(p.scene.obstacles),
            description=p.description,
        )
        rows.append(row)
    if args.json:
        print(json.dumps(rows, indent=1))
        return 0
    # descriptions are long: a column of their own only where they have room
    beside = console.width >= WIDE
    cols: list[tuple[str, Kind]] = [
        ("name", "name"),
        ("from", "name"),
        ("robot", "name"),
        ("dof", "num"),
        ("obstacles", "num"),
        ("legs", "text"),
    ]
    groups = list(dict.fromkeys((r["from"], r["group"]) for r in rows))
    for origin, group in groups:
        members = [r for r in rows if (r["from"], r["group"]) == (origin, group)]
        title = "problems" if not group else f"problems in {group}/"
        if len(groups) > 1 and not group and origin == "./problems":
            title = "problems in ./problems"
        t = table(title, cols + ([("description", "text")] if beside else []), compact=True)
        for r in members:
            cells = [
                r["name"],
                r["from"],
                r["robot"],
                "-" if r["dof"] is None else str(r["dof"]),
                "-" if r["obstacles"] is None else str(r["obstacles"]),
                ", ".join(r["legs"]),
            ]
            t.add_row(*cells, *([r["description"]] if beside else []))
        console.print(t)
        if not beside:
            for r in members:
                console.print(Text.assemble((r["name"], "bold"), f": {r['description']}"))
    return 0


def add_parser(sub: Any) -> None:
    p = sub.add_parser(
        "problems",
        help="list the problems: ./problems first, then the bundled ones (with their "
        "sub-folders: urdf/panda, variants), one table per folder",
    )
    p.add_argument("--json", action="store_true", help="print one JSON document")
    p.set_defaults(func=cmd_problems)
