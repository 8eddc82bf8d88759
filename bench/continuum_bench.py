"""Benchmark of the chord-arc planner (planar continuum robot wrapping obstacles).

Tables:

1. The three problem files ``problems/continuum_case{1,2,3}.toml`` beside the paper's
   Table I (MATLAB 2019a, i7-4790K), for the planner's default settings (the robot's
   radius): median and 90th percentile wall time of ``--runs`` (>= 20) calls of the
   search (``solve_chord_arc`` on the planning query: search + motion check, what the
   paper times; target: p90 at most a tenth of the paper's time) and of the planner's
   whole ``solve`` (also the joint paths and the contact classification of every state;
   target 50 ms), with the machine's load average before and after.
2. The contact classification of the chosen path, batched (the planner's one planar
   call over every state × link × obstacle) against a baseline measured in the same
   run: python-fcl state by state (``CollisionChecker.colliding_pairs`` per state, what
   the planner did before); the ratio and whether both give the same pairs.
3. ``--scaling``: time and solutions as the number of collision points grows from 5 to
   40, on random scenes (rectangles, collision points on their corners) from a numpy
   Generator with a fixed seed.

Writes ``results/continuum_bench.csv`` (and ``results/continuum_scaling.png`` with
``--scaling``) unless ``--no-files``; ``--figures`` also draws each case like the paper's
Fig. 4.

    python bench/continuum_bench.py [--runs 30] [--scaling] [--seed 7] [--figures]
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import math
import os
import platform
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from plannerlab.planners import make_planner
from plannerlab.planners.chord_arc.geometry import (
    ChordArcInputError,
    ChordArcQuery,
    ConvexPolygon,
)
from plannerlab.planners.chord_arc.motion import ChordArcResult, solve_chord_arc
from plannerlab.planners.chord_arc.planner import PAPER_TABLE
from plannerlab.planners.chord_arc.scene import capsule_distances
from plannerlab.planners.chord_arc.settings import ChordArcSettings
from plannerlab.problem.catalog import load_problem

ROOT = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class Timing:
    median_s: float
    p90_s: float
    result: ChordArcResult


def time_solve(query: ChordArcQuery, settings: ChordArcSettings, runs: int) -> Timing:
    """Median and 90th percentile of ``runs`` calls (after one warm-up call)."""
    result = solve_chord_arc(query, settings)
    ts = []
    for _ in range(runs):
        t0 = time.perf_counter()
        solve_chord_arc(query, settings)
        ts.append(time.perf_counter() - t0)
    return Timing(float(np.median(ts)), float(np.percentile(ts, 90)), result)


def random_scene(rng: np.random.Generator, n_points: int, length_m: float = 0.5) -> ChordArcQuery:
    """A random planar scene with ``n_points`` collision points on rectangle corners.

    Non-overlapping rectangles (4-12 cm sides, any yaw) in the box x ∈ [-0.25, 0.25],
    y ∈ [0.08, 0.5] m in front of a port at the origin facing +y; one rectangle straight
    ahead of the port; the target is a free point in the upper band. The collision points
    are ``n_points`` corners drawn without replacement.
    """
    n_rect = math.ceil(n_points / 4) + 1
    rects: list[ConvexPolygon] = []
    discs: list[tuple[float, float, float]] = []  # bounding circles, for non-overlap
    first = True
    while len(rects) < n_rect:
        size = rng.uniform(0.04, 0.12, 2)
        c = (
            (0.0, rng.uniform(0.15, 0.22))
            if first
            else (rng.uniform(-0.25, 0.25), rng.uniform(0.08, 0.5))
        )
        rad = float(np.hypot(*size) / 2)
        if any(np.hypot(c[0] - x, c[1] - y) < rad + r + 0.01 for x, y, r in discs):
            continue
        yaw = 0.0 if first else rng.uniform(0.0, math.pi)
        rects.append(ConvexPolygon.rectangle(c, size, yaw, f"r{len(rects)}"))
        discs.append((c[0], c[1], rad))
        first = False
    corners = np.array([v for r in rects for v in r.vertices_m])
    pick = rng.choice(len(corners), size=n_points, replace=False)
    points = tuple(tuple(corners[i]) for i in np.sort(pick))
    while True:
        target = (float(rng.uniform(-0.15, 0.15)), float(rng.uniform(0.3, 0.45)))
        if all(np.hypot(target[0] - x, target[1] - y) > r + 0.01 for x, y, r in discs):
            break
    return ChordArcQuery((0.0, 0.0), (0.0, 1.0), length_m, tuple(rects), points, target)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=30, help="timed runs per case (>= 20)")
    ap.add_argument("--seed", type=int, default=7, help="seed of the scaling scenes")
    ap.add_argument("--scenes", type=int, default=5, help="random scenes per size")
    ap.add_argument("--scaling-runs", type=int, default=5, help="timed runs per scene")
    ap.add_argument(
        "--max-expansions", type=int, default=20_000, help="search budget of the scaling runs"
    )
    ap.add_argument("--no-files", action="store_true", help="print only")
    ap.add_argument("--figures", action="store_true", help="draw each case to results/")
    ap.add_argument("--scaling", action="store_true", help="also the random-scene scaling table")
    args = ap.parse_args()
    runs = max(20, args.runs)
    console = Console()
    if console.width < 150:  # keep the tables readable when piped
        console = Console(width=150)
    rows: list[dict[str, object]] = []
    load_before = os.getloadavg()

    table = Table(
        title=f"chord_arc on the paper's three cases, the robot's radius (median and p90 of "
        f"{runs} runs)"
    )
    for col in (
        "case",
        "search median [ms]",
        "search p90 [ms]",
        "target [ms]",
        "paper [ms]",
        "p90 / paper",
        "solve median [ms]",
        "solve p90 [ms]",
        "points (paper)",
        "solutions (paper)",
        "zero-thickness",
        "met",
    ):
        table.add_column(escape(col), justify="right")
    classify = Table(
        title="contact classification of the chosen path: batched vs FCL state by state "
        "(baseline, same run)"
    )
    for col in ("case", "states", "batched [ms]", "FCL per state [ms]", "speed-up", "same pairs"):
        classify.add_column(escape(col), justify="right")
    planner = make_planner("chord_arc")
    thin = make_planner("chord_arc", {"inflate_by_radius": False})
    for name, paper in PAPER_TABLE.items():
        case = name.removeprefix("continuum_case")
        problem = load_problem(name)
        query = planner.planning_query(problem, planner.query(problem, 0))
        t = time_solve(query, planner.settings, runs)
        res = t.result
        budget = problem.budget
        rng = np.random.default_rng(0)
        plan = planner.solve(problem, 0, budget, rng)  # warm-up
        solve_s = []
        for _ in range(runs):
            t0 = time.perf_counter()
            plan = planner.solve(problem, 0, budget, rng)
            solve_s.append(time.perf_counter() - t0)
        n_thin = len(thin.solve(problem, 0, budget, rng).extra["solutions"])
        target_s = paper.time_s / 10
        solve_med, solve_p90 = float(np.median(solve_s)), float(np.percentile(solve_s, 90))
        met = t.p90_s <= target_s and solve_med <= 0.05
        table.add_row(
            case,
            f"{t.median_s * 1e3:.2f}",
            f"{t.p90_s * 1e3:.2f}",
            f"{target_s * 1e3:.0f}",
            f"{paper.time_s * 1e3:.0f}",
            f"{t.p90_s / paper.time_s:.3f}",
            f"{solve_med * 1e3:.1f}",
            f"{solve_p90 * 1e3:.1f}",
            f"{len(query.collision_points_m)} ({paper.collision_points})",
            f"{len(res.plans)} ({paper.solutions})",
            str(n_thin),
            "[green]yes[/green]" if met else "[red]no[/red]",
        )
        # the classification of the chosen path: batched planar vs FCL per state
        robot = problem.robot
        real = planner.query(problem, 0)
        names = [o.name for o in real.obstacles]
        reps = max(3, runs // 4)
        t0 = time.perf_counter()
        for _ in range(reps):
            seg = robot.link_segments(plan.path)[..., :2]
            dist = capsule_distances(seg, real.obstacles, robot.link_radius_m)
        batched_s = (time.perf_counter() - t0) / reps
        planar = {
            (robot.link_names[li], names[o])
            for li, o in zip(*np.nonzero((dist < robot.link_radius_m).any(axis=0)), strict=True)
        }
        from plannerlab.collision.fcl_checker import CollisionChecker

        checker = CollisionChecker(robot, problem.scene)
        t0 = time.perf_counter()
        fcl_pairs: set[tuple[str, str]] = set()
        for q in plan.path:
            fcl_pairs |= set(checker.colliding_pairs(q))
        fcl_s = time.perf_counter() - t0
        classify.add_row(
            case,
            str(len(plan.path)),
            f"{batched_s * 1e3:.2f}",
            f"{fcl_s * 1e3:.1f}",
            f"{fcl_s / batched_s:.0f}x",
            "yes" if planar == fcl_pairs else "[red]no[/red]",
        )
        rows.append(
            {
                "table": "cases",
                "case": case,
                "points": len(query.collision_points_m),
                "median_ms": t.median_s * 1e3,
                "p90_ms": t.p90_s * 1e3,
                "solve_median_ms": solve_med * 1e3,
                "solve_p90_ms": solve_p90 * 1e3,
                "solutions": len(res.plans),
                "solutions_zero_thickness": n_thin,
                "geometric": len(res.search.solutions),
                "expansions": res.search.expansions,
                "budget_exhausted": False,
                "paper_ms": paper.time_s * 1e3,
                "paper_solutions": paper.solutions,
                "classify_batched_ms": batched_s * 1e3,
                "classify_fcl_ms": fcl_s * 1e3,
            }
        )
        if args.figures:
            from plannerlab.plot.continuum import draw_case

            draw_case(
                real,
                res,
                ROOT / "results" / f"continuum_case{case}.png",
                title=f"case {case}: {len(res.plans)} solution(s), "
                f"{len(query.collision_points_m)} collision points",
            )
    load_after = os.getloadavg()
    console.print(table)
    console.print(classify)
    console.print(
        f"load average (1, 5, 15 min) before {load_before[0]:.1f} {load_before[1]:.1f} "
        f"{load_before[2]:.1f}, after {load_after[0]:.1f} {load_after[1]:.1f} "
        f"{load_after[2]:.1f}; {os.cpu_count()} cores"
    )
    for r in rows:
        r["load_1min_before"] = load_before[0]
        r["load_1min_after"] = load_after[0]
    if not args.scaling:
        _write(rows, None, args, console)
        return

    rng = np.random.default_rng(args.seed)
    scale = Table(
        title=f"Scaling on random scenes (seed {args.seed}, {args.scenes} scenes per "
        f"size, median of {args.scaling_runs} runs each, budget "
        f"{args.max_expansions} expansions)"
    )
    for col in (
        "collision points",
        "time [ms] median",
        "time [ms] max",
        "solutions median",
        "solutions max",
        "geometric median",
        "expansions median",
        "budget hit",
    ):
        scale.add_column(escape(col), justify="right")
    s_settings = dataclasses.replace(ChordArcSettings(), max_expansions=args.max_expansions)
    sizes = (5, 10, 15, 20, 25, 30, 35, 40)
    curve = []
    for n in sizes:
        times, sols, geo, exp, hit = [], [], [], [], 0
        made = 0
        while made < args.scenes:
            try:
                query = random_scene(rng, n)
                t = time_solve(query, s_settings, args.scaling_runs)
            except ChordArcInputError:  # a target on a corner etc.: draw another scene
                continue
            made += 1
            times.append(t.median_s)
            sols.append(len(t.result.plans))
            geo.append(len(t.result.search.solutions))
            exp.append(t.result.search.expansions)
            hit += t.result.search.budget_exhausted
        scale.add_row(
            str(n),
            f"{np.median(times) * 1e3:.2f}",
            f"{np.max(times) * 1e3:.2f}",
            f"{np.median(sols):.0f}",
            str(max(sols)),
            f"{np.median(geo):.0f}",
            f"{np.median(exp):.0f}",
            f"{hit}/{args.scenes}",
        )
        curve.append((n, float(np.median(times)), float(np.median(sols))))
        rows.append(
            {
                "table": "scaling",
                "case": "",
                "points": n,
                "median_ms": float(np.median(times)) * 1e3,
                "p90_ms": float(np.max(times)) * 1e3,
                "solutions": float(np.median(sols)),
                "geometric": float(np.median(geo)),
                "expansions": float(np.median(exp)),
                "budget_exhausted": hit,
                "paper_ms": "",
                "paper_solutions": "",
            }
        )
    console.print(scale)
    console.print(
        f"[dim]{platform.processor() or platform.machine()}, Python "
        f"{platform.python_version()}, numpy {np.__version__}[/dim]"
    )

    _write(rows, curve, args, console)


def _write(
    rows: list[dict[str, object]],
    curve: list[tuple[int, float, float]] | None,
    args: argparse.Namespace,
    console: Console,
) -> None:
    if args.no_files:
        return
    out = ROOT / "results"
    out.mkdir(exist_ok=True)
    fields: list[str] = []
    for r in rows:
        fields += [k for k in r if k not in fields]
    with open(out / "continuum_bench.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)
    console.print(f"wrote {out / 'continuum_bench.csv'}")
    if curve is None:
        return
    from matplotlib.figure import Figure

    fig = Figure(figsize=(5.5, 3.5), dpi=120)
    ax = fig.add_subplot()
    n_, t_, s_ = zip(*curve, strict=True)
    ax.plot(n_, np.array(t_) * 1e3, "o-", color="tab:blue")
    ax.set_xlabel("collision points")
    ax.set_ylabel("median search time [ms]", color="tab:blue")
    ax.set_yscale("log")
    ax2 = ax.twinx()
    ax2.plot(n_, s_, "s--", color="tab:red")
    ax2.set_ylabel("median solutions", color="tab:red")
    ax.set_title(f"chord-arc search scaling (seed {args.seed})")
    fig.tight_layout()
    fig.savefig(out / "continuum_scaling.png")
    console.print(f"wrote {out / 'continuum_scaling.png'}")


if __name__ == "__main__":
    main()
