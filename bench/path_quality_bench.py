"""What measuring a solved path's quality costs next to planning it: the smallest clearance
along the whole path (every state of the final re-check's grid, in compiled calls:
``run.pipeline.path_clearance_m``) and its roughness, against the leg's planning time,
measured in the same run.

    .venv/bin/python bench/path_quality_bench.py [--repeat 3]

Per case: the legs solved, their planning time (the planners' ``time_s``), the grid
states measured, the measurement's time (best of ``--repeat``) and the ratio
measurement / planning. Budgets are in collision checks; the machine's load is printed.
"""

from __future__ import annotations

import argparse
import os
import time

from plannerlab.problem.catalog import load_problem
from plannerlab.robots.paths import roughness
from plannerlab.run.pipeline import SharedChecker, path_clearance_m, solve_legs

CASES = (
    ("armz_pocket", "gradient.clearance+detour", 20_000),
    ("armz_pocket", "ompl.rrtconnect", 400_000),
    ("armz_inspection", "gradient.clearance+detour", 100_000),
    ("irb6_pick_table", "ompl.rrtconnect", 200_000),
)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    load = os.getloadavg()
    print(f"machine load (1, 5, 15 min): {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}", end="")
    print(f" on {os.cpu_count()} CPUs")
    head = ("problem", "planner", "legs", "plan s", "grid states", "measure s", "measure/plan")
    print(
        f"{head[0]:18}{head[1]:28}{head[2]:>5}{head[3]:>9}{head[4]:>13}{head[5]:>11}{head[6]:>14}"
    )
    for name, planner, checks in CASES:
        problem = load_problem(name)
        shared = SharedChecker(problem)
        budget = problem.budget.replace(max_collision_checks=checks)
        plan = solve_legs(problem, planner, 0, budget=budget, shared=shared)
        solved = [r for r in plan.legs if r.solved]
        checker = shared.get()
        step = problem.joint_step / 4.0
        states = sum(checker.grid_states(r.path, step) for r in solved)

        def measure() -> None:
            for r in solved:  # noqa: B023 - measured at once
                path_clearance_m(checker, r.path, step)  # noqa: B023
                roughness(r.path, problem.robot.continuous)  # noqa: B023

        measure()  # the compiled clearance loaded
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            measure()
            times.append(time.perf_counter() - t0)
        plan_s = sum(r.time_s for r in solved)
        t = min(times)
        ratio = t / plan_s if plan_s > 0 else float("nan")
        print(
            f"{name:18}{planner:28}{len(solved):>5}{plan_s:9.3f}{states:13d}{t:11.4f}{ratio:14.4f}"
        )


if __name__ == "__main__":
    main()
