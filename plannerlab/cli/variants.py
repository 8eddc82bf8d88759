"""``plannerlab variants``: variants of the Arm-Z paper's task on rooms it has never seen.

    plannerlab variants armz_inspection --count 20 --seed 0 --out problems/variants/
    plannerlab variants armz_inspection --count 20 --seed 1 --kind far_ltr,far_rtl \
        --first-index 20 --out problems/variants/
    plannerlab variants armz_inspection --count 40 --seed 2 \
        --kind side,heights,two_windows,deep,deep_far,reverse,shuffled \
        --first-index 40 --max-draws 200 --out problems/variants/

Draws rooms (scaled, shifted, mirrored; the window moved and resized; 20-32 modules;
rooms of more kinds: windows in other walls and at other heights, two windows, deep rooms
with up to 40 modules, visits reversed or shuffled),
places the goals relative to the walls as in the paper, finds a collision-free witness
state with ``--clearance-floor`` of clearance for every goal (a clearance-aware IK, no
planner) and writes the kept variants as problem files (``<out>/armz_inspection_vNN.toml``,
each written atomically). A draw without a witness for some goal is dropped (reported on
stderr) and the next draw is taken. The same seed gives the same files.
"""

# Argument parsing and printing only; the generator is plannerlab.extras.generate_variants
# (plannerlab/problem/variants.py). The docstring above is the command's help.

from __future__ import annotations

import argparse
import shlex
import sys
from typing import Any

from rich.console import Console

from plannerlab import extras as px
from plannerlab.cli.common import add_renamed_flag, positive_int, seed_int

#: tasks the generator knows how to vary
TEMPLATES = ("armz_inspection",)


def _clearance(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"a clearance in metres, got {text!r}") from None
    if not (0.0 <= v < 0.75):
        raise argparse.ArgumentTypeError(f"a clearance in [0, 0.75) m, got {text!r}")
    return v


def add_parser(subparsers: Any) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "variants",
        help="generate variants of the paper's task, each goal with a witness state",
        description=__doc__,
    )
    p.add_argument("task", choices=TEMPLATES, help="the task to vary")
    p.add_argument("--count", type=positive_int, default=20, help="variants to keep")
    p.add_argument("--seed", type=seed_int, default=0, help="seed of the numpy Generator")
    p.add_argument(
        "--out", default="problems/variants", metavar="DIR", help="folder for the problem files"
    )
    p.add_argument(
        "--clearance-floor",
        type=_clearance,
        default=0.04,
        metavar="M",
        help="clearance every witness state keeps at least [m] (its [witness] clearance_floor_m)",
    )
    add_renamed_flag(p, "--min-clearance", "--clearance-floor", type=_clearance, metavar="M")
    p.add_argument(
        "--max-draws",
        type=positive_int,
        default=None,
        metavar="N",
        help="give up after N draws (default: 3 x --count)",
    )
    p.add_argument(
        "--kind",
        default="paper",
        metavar="K[,K...]",
        help="kinds of variant, taken in turn: paper (A-E in the paper's order), far_ltr, "
        "far_rtl (ending on the far wall, visited left to right / right to left); rooms of "
        "more kinds: side (the window in a side wall), roof (in the ceiling; no witness "
        "found yet), heights (low or high, visited in reverse), two_windows (visited "
        "shuffled), deep, deep_far (the far wall 8-10 m in), reverse, shuffled (the "
        "paper's rooms in those orders)",
    )
    p.add_argument(
        "--first-index",
        type=int,
        default=0,
        metavar="N",
        help="number of the first variant (its file armz_inspection_vNN.toml)",
    )
    p.set_defaults(func=cmd_variants)
    return p


def cmd_variants(args: argparse.Namespace, console: Console) -> int:

    out = args.out
    from pathlib import Path

    if Path(out).exists() and not Path(out).is_dir():
        raise px.VariantError(f"--out {out}: a folder, but a file is in the way")
    command = "plannerlab variants " + " ".join(
        shlex.quote(a)
        for a in [
            args.task,
            "--count",
            str(args.count),
            "--seed",
            str(args.seed),
            "--clearance-floor",
            f"{args.clearance_floor:g}",
        ]
        + ([] if args.kind == "paper" else ["--kind", args.kind])
        + ([] if args.first_index == 0 else ["--first-index", str(args.first_index)])
    )

    def progress(line: str) -> None:
        print(line, file=sys.stderr, flush=True)

    kept = px.generate_variants(
        args.count,
        args.seed,
        min_clearance_m=args.clearance_floor,
        max_draws=args.max_draws,
        command=command,
        progress=progress,
        kinds=tuple(k.strip() for k in args.kind.split(",") if k.strip()),
        first_index=args.first_index,
    )
    for path in px.write_variants(kept, out):
        print(path)
    return 0
