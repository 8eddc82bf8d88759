"""Where a ``native.rrtconnect`` solve spends its time: per solve, the checker's build
(before the clock), the goal pool, the search, the shortcuts, the re-check and the
result, and the compiled kernels' share of the planning time (``time_s``), with the
machine's load.

Each phase is timed by wrapping its function for this process only (the planner runs
as it always does). MotionBenchMaker problems (``mbm SCENARIO N``: the first N of a
scenario, 10 s each, seed = index) or bundled problems by name (seeds 0 and 1, 3 s each).

Run::

    PYTHONPATH=. .venv/bin/python bench/native_phases.py mbm box 20 [--folder /tmp/mbm]
    PYTHONPATH=. .venv/bin/python bench/native_phases.py \
        armz_pocket,armz_window,armz_cavity,armz_thin_wall

It runs on older checkouts too (phases they lack are left out), for a before/after.
"""

from __future__ import annotations

import argparse
import collections
import os
import time
from pathlib import Path
from typing import Any

import numpy as np

import plannerlab.collision.fcl_checker as FC
import plannerlab.planners.native.kernels as K
import plannerlab.planners.native.solve as S
from plannerlab.planners import make_planner
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import Budget, parse_problem

PHASES = collections.defaultdict(float)


def timed(owner: Any, name: str, label: str) -> None:
    """Replace ``owner.name`` by a wrapper adding its time to ``PHASES[label]``."""
    f = getattr(owner, name)

    def wrapper(*a: Any, **k: Any) -> Any:
        t0 = time.perf_counter()
        try:
            return f(*a, **k)
        finally:
            PHASES[label] += time.perf_counter() - t0

    setattr(owner, name, wrapper)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("what", help="'mbm' or bundled problem names, comma-separated")
    ap.add_argument("scenario", nargs="?", default="box")
    ap.add_argument("count", nargs="?", type=int, default=20)
    ap.add_argument("--folder", type=Path, default=Path("/tmp/mbm"))
    args = ap.parse_args()
    timed(FC, "problem_checker", "checker build (before the clock)")
    timed(S, "fill_goal_pool", "goal pool")
    timed(S.NativeSolve, "search", "search")
    timed(K, "rrtc_entry", "  rrtc_entry (kernel)")
    timed(S.NativeSolve, "simplify", "shortcuts")
    timed(K, "shortcut_entry", "  shortcut_entry (kernel)")
    timed(S.NativeSolve, "checked", "re-check and result")
    timed(FC.CollisionChecker, "check_path", "  check_path")
    timed(FC.CollisionChecker, "first_invalid", "    first_invalid (core)")
    timed(FC.CollisionChecker, "densify", "    densify (numpy road)")
    timed(S.NativeSolve, "result", "  result")
    if args.what == "mbm":
        files = sorted(args.folder.glob(f"{args.scenario}_[0-9]*.toml"))[: args.count]
        problems = [(f.stem, parse_problem(f)) for f in files]
        budget, seeds = Budget(time_limit_s=10.0), (0,)
    else:
        problems = [(n, load_problem(n)) for n in args.what.split(",")]
        budget, seeds = Budget(time_limit_s=3.0), (0, 1)
    planner = make_planner("native.rrtconnect")
    for _, p in problems:  # kernels loaded, each problem solved once, untimed
        planner.solve(p, 0, Budget(max_iterations=1), np.random.default_rng(99))
    PHASES.clear()
    load0 = os.getloadavg()[0]
    wall = plan = 0.0
    checks = 0
    for i, (_, p) in enumerate(problems):
        for s in seeds:
            t0 = time.perf_counter()
            r = planner.solve(p, 0, budget, np.random.default_rng(7 * i + s))
            wall += time.perf_counter() - t0
            plan += r.time_s
            checks += r.collision_checks
    k = len(problems) * len(seeds)
    kernels = sum(v for n, v in PHASES.items() if "(kernel)" in n)
    print(
        f"{args.what} ({k} solves; load average {load0:.1f} -> {os.getloadavg()[0]:.1f}): "
        f"per solve whole call {wall / k * 1e3:.2f} ms, time_s {plan / k * 1e3:.2f} ms, "
        f"{checks / k:,.0f} checks, {checks / plan:,.0f} checks/s of time_s; the kernels "
        f"{kernels / plan:.0%} of time_s"
    )
    for label, v in PHASES.items():
        print(f"  {label:34s} {v / k * 1e3:8.2f} ms")


if __name__ == "__main__":
    main()
