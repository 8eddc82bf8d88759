"""What the subcommands share: budget and leg flags, setting overrides; numbers are
formatted by :func:`plannerlab.record.cells.fmt`, as in the tables."""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from plannerlab.errors import PlannerlabError, UnknownNameError, warn_renamed

RESULTS_DIR = Path("results")


def add_renamed_flag(p: argparse.ArgumentParser, old: str, new: str, **kwargs: Any) -> None:
    """``old``, a flag renamed ``new`` (already added to ``p``): still read for one release,
    into ``new``'s value, with a warning naming ``new``; not shown in the help."""

    class _Renamed(argparse.Action):
        def __call__(
            self,
            parser: argparse.ArgumentParser,
            namespace: argparse.Namespace,
            values: Any,
            option_string: str | None = None,
        ) -> None:
            warn_renamed(parser.prog, old, new)
            setattr(namespace, self.dest, values)

    dest = new.lstrip("-").replace("-", "_")
    p.add_argument(old, action=_Renamed, dest=dest, help=argparse.SUPPRESS, **kwargs)


def parse_overrides(items: Sequence[str] | None) -> dict[str, str]:
    """``--set KEY=VALUE`` items -> ``{key: value}`` (values stay strings; the planner's
    settings coerce them, see :func:`plannerlab.planners.base.with_overrides`)."""
    return {key: value for _, key, value in _split_sets(items, scoped=False)}


def parse_scoped_overrides(
    items: Sequence[str] | None, planners: Sequence[str]
) -> dict[str, dict[str, str]]:
    """``--set PLANNER:KEY=VALUE`` items -> ``{planner: {key: value}}``; the planner must be
    one of ``planners``."""
    out: dict[str, dict[str, str]] = {}
    for planner, key, value in _split_sets(items, scoped=True):
        if planner not in planners:
            raise UnknownNameError("planner in --set (not in --planners)", planner, planners)
        out.setdefault(planner, {})[key] = value
    return out


def _split_sets(items: Sequence[str] | None, *, scoped: bool) -> list[tuple[str, str, str]]:
    """The one parser of ``--set``: (planner or "", key, value) per item."""
    form = "PLANNER:KEY=VALUE" if scoped else "KEY=VALUE"
    out = []
    for item in items or []:
        lhs, eq, value = item.partition("=")
        planner, colon, key = lhs.rpartition(":") if scoped else ("", "", lhs)
        if not eq or not key.strip() or (scoped and (not colon or not planner.strip())):
            raise PlannerlabError(f"--set expects {form}, got {item!r}")
        out.append((planner.strip(), key.strip(), value.strip()))
    return out


# ------------------------------------------------------------------ argument types
# argparse reports a type's ArgumentTypeError as "argument --flag: message" and exits 2.
def positive_int(text: str) -> int:
    """An integer >= 1 (budgets)."""
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {v}")
    return v


def seed_int(text: str) -> int:
    """A seed: an integer in [0, 2**63)."""
    try:
        v = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, got {text!r}") from None
    if not 0 <= v < 2**63:
        raise argparse.ArgumentTypeError(f"expected a whole number in [0, 2^63), got {v}")
    return v


def positive_seconds(text: str) -> float:
    """A finite duration > 0 [s]."""
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected seconds > 0, got {text!r}") from None
    if not math.isfinite(v) or v <= 0:
        raise argparse.ArgumentTypeError(f"expected a finite number of seconds > 0, got {text}")
    return v


def leg_spec(text: str) -> str:
    """``all`` or comma-separated leg names / indices, none empty."""
    parts = [x.strip() for x in text.split(",")]
    if not text.strip() or any(not x for x in parts):
        raise argparse.ArgumentTypeError(
            f"expected 'all' or comma-separated leg names or indices (e.g. 0,2), got {text!r}"
        )
    return text


def add_budget_args(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--max-iterations",
        type=positive_int,
        metavar="N",
        help="iteration budget per leg (default: the problem file's [budget])",
    )
    p.add_argument(
        "--max-checks",
        type=positive_int,
        metavar="N",
        help="collision-check budget per leg (default: the problem file's [budget])",
    )
    p.add_argument(
        "--time-limit",
        type=positive_seconds,
        metavar="S",
        help="time limit per leg [s] (default: the problem file's [budget])",
    )


def budget_from_args(problem: Any, args: argparse.Namespace) -> Any:
    return problem.budget.replace(
        max_iterations=args.max_iterations,
        max_collision_checks=args.max_checks,
        time_limit_s=args.time_limit,
    )


def require_display(gui: bool) -> None:
    """``--gui`` opens PyBullet's window: on Linux that needs an X display."""
    if gui and sys.platform.startswith("linux") and not os.environ.get("DISPLAY"):
        raise PlannerlabError(
            "--gui opens PyBullet's window and needs a display, but DISPLAY is not set: "
            "run under a desktop session or `xvfb-run -a plannerlab ...`, or drop --gui "
            "(`plannerlab animate PLAN.json` shows the motion without a display)"
        )
