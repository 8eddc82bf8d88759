"""`plannerlab animate`: an animation of a plan's planned and executed motion."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from rich.console import Console

from plannerlab import extras as px
from plannerlab.cli.plot import plan_executions
from plannerlab.errors import PlannerlabError


def cmd_animate(args: argparse.Namespace, console: Console) -> int:
    import plannerlab as pl

    if args.frames < 2:
        raise PlannerlabError(f"--frames: expected >= 2, got {args.frames}")
    if args.fps < 1:
        raise PlannerlabError(f"--fps: expected >= 1, got {args.fps}")
    plan, problem = px.read_checked_plan(args.plan)
    out = Path(args.out) if args.out else Path(args.plan).with_suffix(f".{args.format}")
    executions = plan_executions(args.plan)
    note = "with its execution record (PLAN.exec.json)"
    if not executions and not args.no_execute:
        with console.status(f"executing {len(plan.legs)} legs in PyBullet (none recorded)"):
            executions = px.execute_results(problem, plan.legs)
        note = "executed now (no PLAN.exec.json beside the plan; `plannerlab execute` writes one)"
    elif not executions:
        note = "planned motion only (--no-execute)"
    with console.status(f"drawing {args.frames} frames"):
        path = pl.animate_plan(plan, problem, out, executions, max_frames=args.frames, fps=args.fps)
    if args.json:
        print(json.dumps({"animation": str(path), "executed": bool(executions)}))
    else:
        console.print(f"wrote {path} ({note})", soft_wrap=True, highlight=False)
    return 0


def add_parser(sub: Any) -> None:
    p = sub.add_parser(
        "animate",
        help="animate a plan: planned and executed motion, 3D, front and top views",
        description="Write an animation of PLAN.json's motion (GIF, or MP4 with ffmpeg): "
        "the planned arm, PyBullet's arm, both tip traces, the obstacles and the goal "
        "regions; the last frames show where PyBullet's arm really ended. A plan without "
        "an execution record is executed first (headless).",
    )
    p.add_argument("plan", help="PLAN.json written by solve/execute")
    p.add_argument("--out", help="animation file (default: beside the plan, PLAN.gif)")
    p.add_argument(
        "--format", choices=("gif", "mp4"), default="gif", help="gif (default) or mp4 (ffmpeg)"
    )
    p.add_argument("--frames", type=int, default=90, help="frames of motion (default 90)")
    p.add_argument("--fps", type=int, default=12, help="frames per second (default 12)")
    p.add_argument(
        "--no-execute", action="store_true", help="animate the plan only, never run PyBullet"
    )
    p.add_argument("--json", action="store_true", help="print the file written as JSON")
    p.set_defaults(func=cmd_animate)
