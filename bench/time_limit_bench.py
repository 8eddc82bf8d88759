"""Do the planners hold their time limit? Every registered planner, on rooms where it does
not finish early, with only a time limit.

Usage:

    PYTHONPATH=. python bench/time_limit_bench.py [LIMIT_S] [PROBLEM,...]

Defaults: 0.3 s on armz_inspection, armz_pocket and irb6_case1.

Each planner solves leg 0 once (seed 1) with ``Budget(time_limit_s=LIMIT_S)``; the compiled
collision core and OMPL are loaded before the first clock starts (as in a ``compare`` trial).
Prints per planner and problem the status, the wall time of ``solve`` and its ratio to the
limit; ``over`` marks a ratio above 1.01 plus one 50 ms poll interval. Closed-loop planners
run with a PyBullet world as their stepper.
"""

from __future__ import annotations

import sys
import time


def main(argv: list[str]) -> int:
    import numpy as np

    import plannerlab.planners.ompl  # noqa: F401 - OMPL loaded once, before any clock
    from plannerlab.collision.fcl_checker import CollisionChecker
    from plannerlab.errors import PlannerlabError
    from plannerlab.planners import REGISTRY, make_planner
    from plannerlab.problem.catalog import load_problem
    from plannerlab.problem.load import Budget

    try:
        limit_s = float(argv[0]) if argv else 0.3
    except ValueError:
        limit_s = float("nan")
    if not limit_s > 0 or limit_s == float("inf"):
        print(f"usage: time_limit_bench.py [LIMIT_S > 0] [PROBLEM,...]; got {argv[0]!r}")
        return 2
    problems = (
        argv[1].split(",") if len(argv) > 1 else ["armz_inspection", "armz_pocket", "irb6_case1"]
    )
    worst = 0.0
    print(f"{'problem':18s} {'planner':32s} {'status':17s} {'wall s':>7s} {'/limit':>7s}")
    try:
        loaded = [load_problem(name_p) for name_p in problems]
    except PlannerlabError as exc:
        print(f"error: {exc}")
        return 2
    for name_p, problem in zip(problems, loaded, strict=True):
        CollisionChecker(problem.robot, problem.scene)  # compile / load the core first
        for name, entry in REGISTRY.items():
            if entry.robots is not None and problem.robot.kind not in entry.robots:
                continue
            planner = make_planner(name)
            budget = Budget(time_limit_s=limit_s)
            rng = np.random.default_rng(1)
            if entry.needs_stepper:
                from plannerlab.sim import SimWorld

                with SimWorld(problem.robot, problem.scene, gravity_mps2=(0.0, 0.0, 0.0)) as w:
                    t0 = time.perf_counter()
                    r = planner.solve(problem, 0, budget, rng, stepper=w)
                    wall_s = time.perf_counter() - t0
            else:
                t0 = time.perf_counter()
                r = planner.solve(problem, 0, budget, rng)
                wall_s = time.perf_counter() - t0
            ratio = wall_s / limit_s
            worst = max(worst, ratio)
            over = "  over" if wall_s > limit_s * 1.01 + 0.05 else ""
            print(
                f"{name_p:18s} {name:32s} {r.status.value:17s} {wall_s:7.3f} {ratio:7.2f}{over}",
                flush=True,
            )
    print(f"worst ratio to the limit: {worst:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
