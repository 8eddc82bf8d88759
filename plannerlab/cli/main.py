"""The ``plannerlab`` command: argument parsing and printing only."""

from __future__ import annotations

import argparse
import contextlib
import io
import logging
import os
import re
import sys
import warnings
from collections.abc import Iterator, Sequence

from rich.console import Console
from rich.text import Text

from plannerlab.cli import (
    animate,
    execute,
    planners,
    plot,
    problems,
    robot,
    solve,
    variants,
    view,
)
from plannerlab.cli.tables import make_console
from plannerlab.errors import PlannerlabError, RenamedWarning

DESCRIPTION = """\
Compare motion planners on hyper-redundant, industrial and continuum robots.

A problem is a TOML file (see docs/problem-format.md); give its path, or a name that is
looked up in ./problems first, then among the bundled problems (plannerlab problems).

typical use:
  plannerlab problems                                   list the problems
  plannerlab planners                                   list the planners
  plannerlab solve armz_pocket --planner ompl.rrtconnect --seed 3
  plannerlab execute results/plans/armz_pocket__ompl.rrtconnect__seed3.json
  plannerlab plot results/plans/armz_pocket__ompl.rrtconnect__seed3.json
  plannerlab compare armz_pocket --planners gradient,ompl.rrtconnect --seeds 0-4
  plannerlab robot path/to/arm.urdf                     what plannerlab makes of a URDF

Every subcommand has its own help: plannerlab SUBCOMMAND --help.
Exit codes: 0 done, 1 --strict and a leg failed, 2 bad input (the message names the
file, the key or flag, and what was expected), 130 interrupted.
"""


def _plain(text: str) -> str:
    """Help text without reStructuredText markup (docstrings double as descriptions)."""
    text = re.sub(r":[a-z]+:`~?([^`]+)`", r"\1", text)
    return text.replace("``", "'")


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Keeps the descriptions' line breaks and appends each flag's default to its help
    (unless the help already states it, or there is no default)."""

    def _format_text(self, text: str) -> str:
        return super()._format_text(_plain(text))

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if "default" in text or "%(default)" in text:
            return text
        default = action.default
        if default is None or default is False or default == argparse.SUPPRESS:
            return text
        if not action.option_strings:
            return text
        if isinstance(default, list) and not default:
            return text
        return f"{text} (default: %(default)s)"


@contextlib.contextmanager
def engine_output_kept_off_stdout(verbose: bool) -> Iterator[None]:
    """Keep what C code (PyBullet's banner and ``argv[0]=``, OMPL's log lines) writes to
    file descriptor 1 off stdout: it goes to stderr with ``-v``, else to /dev/null.
    Python's ``sys.stdout`` keeps writing to the real stdout, so ``--json`` prints exactly
    one JSON document. Does nothing if stdout is not file descriptor 1 (e.g. captured)."""
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, io.UnsupportedOperation, ValueError):
        fd = -1
    if fd != 1:
        yield
        return
    sys.stdout.flush()
    saved = os.dup(1)
    target = os.dup(2) if verbose else os.open(os.devnull, os.O_WRONLY)
    os.dup2(target, 1)
    os.close(target)
    previous = sys.stdout
    real = open(  # noqa: SIM115 - closed below
        saved, "w", encoding=previous.encoding, errors="replace", closefd=False, buffering=1
    )
    sys.stdout = real
    try:
        yield
    finally:
        real.flush()
        sys.stdout = previous
        os.dup2(saved, 1)
        os.close(saved)
        real.close()


# ---------------------------------------------------------------------- parser
def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="plannerlab", description=DESCRIPTION, formatter_class=HelpFormatter
    )
    parser.add_argument(
        "-v",
        "--verbose",
        action="store_true",
        help="log at INFO level and let PyBullet's and OMPL's own output through (on stderr)",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="SUBCOMMAND")

    for module in (problems, planners, solve, execute, plot, animate, view, variants, robot):
        module.add_parser(sub)
    from plannerlab.cli.ik import add_ik_parser

    add_ik_parser(sub)
    from plannerlab.cli.compare import add_compare_parser

    add_compare_parser(sub)
    from plannerlab.cli.continuum import add_continuum_parser

    add_continuum_parser(sub)
    from plannerlab.cli.importer import add_parser as add_import_parser

    add_import_parser(sub)
    for name, p in sub.choices.items():
        p.formatter_class = HelpFormatter
        if not p.description:
            help_text = next((a.help for a in sub._choices_actions if a.dest == name), None)
            p.description = help_text
    return parser


def _error_console() -> Console:
    """stderr, printing messages as written (they name keys in brackets: "[goals[0].n]"),
    one line each: a file path is never broken by an inserted line break (soft wrap; the
    terminal folds long lines itself)."""
    return Console(stderr=True, markup=False, soft_wrap=True)


def _show_renamed(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: object = None,
    line: str | None = None,
) -> None:
    """A renamed setting, key or flag as one line on stderr (``warning: ...``); any other
    warning as Python shows it."""
    if issubclass(category, RenamedWarning):
        _error_console().print(Text.assemble(("warning:", "yellow"), f" {message}"))
    else:
        _PYTHON_SHOWWARNING(message, category, filename, lineno, file, line)  # type: ignore[arg-type]


_PYTHON_SHOWWARNING = warnings.showwarning


def main(argv: Sequence[str] | None = None) -> int:
    with warnings.catch_warnings():
        warnings.showwarning = _show_renamed
        return _main(argv)


def _main(argv: Sequence[str] | None) -> int:
    args = build_parser().parse_args(argv)
    logging.basicConfig(
        level=logging.INFO if args.verbose else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
    )
    to_stderr = bool(getattr(args, "json", False))
    # the terminal's width; piped: COLUMNS, the terminal's, or 100 (cli.tables)
    console = make_console(stderr=to_stderr)
    # OMPL's own log lines (forwarded to this logger) reach the terminal only with -v
    ompl_logger = logging.getLogger("plannerlab.ompl")
    ompl_level = ompl_logger.level
    if not args.verbose:
        ompl_logger.setLevel(logging.ERROR)
    try:
        with engine_output_kept_off_stdout(args.verbose):
            return int(args.func(args, console) or 0)
    except PlannerlabError as exc:
        _error_console().print(Text.assemble(("error:", "red"), f" {exc}"), highlight=False)
        return 2
    except OSError as exc:
        if exc.filename is None:
            raise
        # a path given on the command line (--out, a plan or problem file) that cannot be
        # read or written
        msg = f"{exc.filename}: {exc.strerror or exc}"
        _error_console().print(Text.assemble(("error:", "red"), f" {msg}"), highlight=False)
        return 2
    except KeyboardInterrupt:
        _error_console().print("interrupted")
        return 130
    finally:
        ompl_logger.setLevel(ompl_level)


if __name__ == "__main__":
    sys.exit(main())
