"""What the subcommands share: number formatting, budget and leg flags, setting overrides."""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from plannerlab.errors import PlannerlabError

RESULTS_DIR = Path("results")


def fmt(x: Any, digits: int = 3) -> str:
    if x is None:
        return "-"
    if isinstance(x, float):
        if math.isnan(x):
            return "-"
        return f"{x:.{digits}g}" if abs(x) < 1e4 else f"{x:.0f}"
    return str(x)


def parse_overrides(items: Sequence[str] | None) -> dict[str, str]:
    out: dict[str, str] = {}
    for item in items or []:
        if "=" not in item:
            raise PlannerlabError(f"--set expects KEY=VALUE, got {item!r}")
        k, v = item.split("=", 1)
        out[k.strip()] = v.strip()
    return out


def add_budget_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("--max-iterations", type=int, help="iteration budget per leg")
    p.add_argument("--max-checks", type=int, help="collision-check budget per leg")
    p.add_argument("--time-limit", type=float, help="time limit per leg [s]")


def budget_from_args(problem: Any, args: argparse.Namespace) -> Any:
    return problem.budget.replace(
        max_iterations=args.max_iterations,
        max_collision_checks=args.max_checks,
        time_limit_s=args.time_limit,
    )


def legs_from_spec(problem: Any, spec: str | None) -> list[int] | None:
    if not spec or spec == "all":
        return None
    return [problem.resolve_leg(x.strip()) for x in spec.split(",")]
