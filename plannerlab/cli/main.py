"""The ``plannerlab`` command: argument parsing and printing only.

plannerlab problems
plannerlab planners
plannerlab solve PROBLEM --planner NAME --seed N [--json] [--out PLAN.json]
plannerlab execute PROBLEM --planner NAME --seed N | plannerlab execute PLAN.json
plannerlab plot PLAN.json [--out DIR]
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Sequence

from rich.console import Console
from rich.markup import escape

from plannerlab.cli import execute, planners, plot, problems, solve
from plannerlab.errors import PlannerlabError


# ---------------------------------------------------------------------- parser
def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="plannerlab", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log at INFO level")
    sub = parser.add_subparsers(dest="command", required=True)

    for module in (problems, planners, solve, execute, plot):
        module.add_parser(sub)
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
