"""Benchmark of the chord-arc search (planar continuum robot wrapping obstacles).

Two tables:

1. The three problem files ``problems/continuum_case{1,2,3}.toml`` beside the paper's
   Table I (MATLAB 2019a, i7-4790K): median wall time of ``--runs`` (>= 20) calls of
   ``solve_chord_arc`` (search + motion check, time.perf_counter), collision points,
   solutions found; target: at most a tenth of the paper's time.
2. Scaling: time and solutions as the number of collision points grows from 5 to 40, on
   random scenes (rectangles, collision points on their corners) from a numpy Generator
   with a fixed seed.

Writes ``results/continuum_bench.csv`` and ``results/continuum_scaling.png`` (unless
``--no-files``); ``--figures`` also draws each case like the paper's Fig. 4.

    python bench/continuum_bench.py [--runs 30] [--seed 7] [--figures]
"""

from __future__ import annotations

import argparse
import csv
import math
import platform
import time
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from plannerlab.planners.chord_arc_search import (
    ChordArcInputError,
    ChordArcQuery,
    ChordArcResult,
    ChordArcSettings,
    ConvexPolygon,
    query_from_toml_data,
    solve_chord_arc,
)

ROOT = Path(__file__).resolve().parents[1]
#: the paper's Table I: case -> (time [s], collision points, solutions)
PAPER = {1: (0.07, 8, 2), 2: (0.06, 6, 2), 3: (0.04, 5, 1)}


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
    args = ap.parse_args()
    runs = max(20, args.runs)
    console = Console()
    if console.width < 150:  # keep the tables readable when piped
        console = Console(width=150)
    settings = ChordArcSettings()
    rows: list[dict[str, object]] = []

    table = Table(title=f"Chord-arc search on the paper's three cases (median of {runs} runs)")
    for col in (
        "case",
        "time [ms] median",
        "p90 [ms]",
        "target [ms]",
        "paper [ms]",
        "collision points (paper)",
        "solutions (paper)",
        "geometric / dropped",
        "expansions",
        "arcs checked",
        "met",
    ):
        table.add_column(escape(col), justify="right")
    for case, (paper_s, paper_pts, paper_sol) in PAPER.items():
        with open(ROOT / "problems" / f"continuum_case{case}.toml", "rb") as f:
            query = query_from_toml_data(tomllib.load(f))
        t = time_solve(query, settings, runs)
        res = t.result
        target_s = paper_s / 10
        met = t.median_s <= target_s
        table.add_row(
            str(case),
            f"{t.median_s * 1e3:.2f}",
            f"{t.p90_s * 1e3:.2f}",
            f"{target_s * 1e3:.0f}",
            f"{paper_s * 1e3:.0f}",
            f"{len(query.collision_points_m)} ({paper_pts})",
            f"{len(res.plans)} ({paper_sol})",
            f"{len(res.search.solutions)} / {len(res.dropped)}",
            str(res.search.expansions),
            str(res.search.arcs_checked),
            "[green]yes[/green]" if met else "[red]no[/red]",
        )
        rows.append(
            {
                "table": "cases",
                "case": case,
                "points": len(query.collision_points_m),
                "median_ms": t.median_s * 1e3,
                "p90_ms": t.p90_s * 1e3,
                "solutions": len(res.plans),
                "geometric": len(res.search.solutions),
                "expansions": res.search.expansions,
                "budget_exhausted": False,
                "paper_ms": paper_s * 1e3,
                "paper_solutions": paper_sol,
            }
        )
        if args.figures:
            from plannerlab.plot.continuum import draw_case

            draw_case(
                query,
                res,
                ROOT / "results" / f"continuum_case{case}.png",
                title=f"case {case}: {len(res.plans)} solution(s), "
                f"{len(query.collision_points_m)} collision points",
            )
    console.print(table)

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
    s_settings = ChordArcSettings(max_expansions=args.max_expansions)
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

    if args.no_files:
        return
    out = ROOT / "results"
    out.mkdir(exist_ok=True)
    with open(out / "continuum_bench.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 3.5), dpi=120)
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
    plt.close(fig)
    console.print(f"wrote {out / 'continuum_bench.csv'} and {out / 'continuum_scaling.png'}")


if __name__ == "__main__":
    main()
