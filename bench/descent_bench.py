"""The compiled clearance descent against the numpy one, in one run, on the same task.

Plans every leg of a problem (default: the seven-leg ``armz_inspection``) with a
clearance-descent planner (default ``gradient.clearance+detour``) through
``run.pipeline.solve_legs`` once with ``backend = "numpy"`` and ``--repeats`` times with
``backend = "compiled"`` (the fastest repeat counts), and prints per backend the
planning time (the legs' ``time_s``: from the tracker's start, the field built before),
the process CPU time of the whole call, the iterations, the time per iteration, the
ratio numpy / compiled, and whether both took the same path: the largest joint
difference [rad] of the two plans leg by leg (each leg starts where that plan's previous
leg ended, so a difference carries over and grows), and of each compiled leg re-planned
from the numpy plan's own start of that leg (the iterates of one descent).

    PYTHONPATH=. .venv/bin/python bench/descent_bench.py [--problem armz_inspection]
        [--planner gradient.clearance+detour] [--seed 0] [--repeats 3]

The machine's load inflates both times alike; the CPU time column is less affected by
other processes than the wall-clock planning time.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from plannerlab.planners import make_planner
from plannerlab.problem.catalog import load_problem
from plannerlab.run.pipeline import canonical_result, leg_rng, solve_legs


def _run(problem, planner: str, seed: int, backend: str):
    cpu0 = time.process_time()
    plan = solve_legs(problem, planner, seed, overrides={"backend": backend})
    cpu_s = time.process_time() - cpu0
    planning_s = sum(r.time_s for r in plan.legs)
    iterations = sum(r.iterations for r in plan.legs)
    return plan, planning_s, cpu_s, iterations


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--problem", default="armz_inspection")
    ap.add_argument("--planner", default="gradient.clearance+detour")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--repeats", type=int, default=3, help="compiled runs (the fastest counts)")
    args = ap.parse_args()
    problem = load_problem(args.problem)
    # load (or compile) the compiled core once outside the measurement
    solve_legs(problem, args.planner, args.seed, legs=[0], overrides={"backend": "compiled"})

    rows = {}
    plan_np, *rows["numpy"] = _run(problem, args.planner, args.seed, "numpy")
    best = None
    for _ in range(max(1, args.repeats)):
        plan_c, planning_s, cpu_s, it = _run(problem, args.planner, args.seed, "compiled")
        if best is None or planning_s < best[0]:
            best = (planning_s, cpu_s, it)
    assert best is not None
    rows["compiled"] = list(best)

    load = ", ".join(f"{v:.1f}" for v in os.getloadavg())
    print(
        f"{args.problem} / {args.planner} / seed {args.seed}: {len(plan_np.legs)} legs; "
        f"{os.cpu_count()} CPUs, load average {load} (1, 5, 15 min) at the end"
    )
    print(
        f"{'backend':<9} {'solved':>6} {'iterations':>10} {'planning s':>10} {'CPU s':>7} "
        f"{'ms/iter':>8} {'CPU ms/iter':>11}"
    )
    for (name, (planning_s, cpu_s, it)), plan in zip(rows.items(), (plan_np, plan_c), strict=True):
        solved = sum(r.solved for r in plan.legs)
        print(
            f"{name:<9} {solved:>3}/{len(plan.legs):<2} {it:>10} {planning_s:>10.3f} "
            f"{cpu_s:>7.3f} {1e3 * planning_s / max(it, 1):>8.3f} "
            f"{1e3 * cpu_s / max(it, 1):>11.3f}"
        )
    ratio = rows["numpy"][0] / max(rows["compiled"][0], 1e-12)
    print(f"numpy / compiled planning time: {ratio:.1f}x")
    worst = 0.0
    same_shape = True
    for a, b in zip(plan_np.legs, plan_c.legs, strict=True):
        if a.path.shape != b.path.shape:
            same_shape = False
            break
        worst = max(worst, float(np.max(np.abs(a.path - b.path))))
    if same_shape:
        print(f"same path: largest joint difference {worst:.3g} rad over the chained legs")
    else:
        print("paths differ in length: the two backends took different steps")
    compiled = make_planner(args.planner, {"backend": "compiled"})
    per_leg = []
    for r in plan_np.legs:
        again = canonical_result(
            compiled.solve(
                problem, r.leg, problem.budget, leg_rng(args.seed, r.leg), q_start=r.path[0]
            )
        )
        same = again.path.shape == r.path.shape
        per_leg.append(f"{float(np.max(np.abs(again.path - r.path))):.2g}" if same else "differ")
    print("each leg from the numpy plan's start of it: largest joint difference [rad]:")
    print("  " + ", ".join(per_leg))


if __name__ == "__main__":
    main()
