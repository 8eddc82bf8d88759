"""Execution wall time and tracking: retimed (toppra) against densified waypoints.

Usage (the plan is made first, on a fixed seed and collision-check budget):

    PYTHONPATH=. python bench/execution_bench.py            # solves the default plan
    PYTHONPATH=. python bench/execution_bench.py PLAN.json  # any plan file

The default plan is ``plannerlab solve armz_inspection --planner ompl.rrtconnect --legs
enter --seed 2 --max-checks 50000`` (seed 1 ends approximate within that budget). Both
timings execute the same legs in the same process, one after the other; the script prints
each one's wall time, simulated duration, maximum joint tracking error and verdict, and
the wall-time ratio waypoints / toppra.
"""

from __future__ import annotations

import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def main(argv: list[str]) -> int:
    from plannerlab.record.files import versions
    from plannerlab.record.plan import Plan
    from plannerlab.sim.execute import execute_legs

    if argv:
        plan_path = Path(argv[0])
    else:
        plan_path = Path(tempfile.mkdtemp(prefix="plannerlab_exec_bench_")) / "plan.json"
        cmd = [
            sys.executable, "-m", "plannerlab", "solve", "armz_inspection",
            "--planner", "ompl.rrtconnect", "--legs", "enter", "--seed", "2",
            "--max-checks", "50000", "--out", str(plan_path),
        ]  # fmt: skip
        print("$", " ".join(cmd[1:]))
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    plan = Plan.load(plan_path)
    problem = plan.load_problem()
    paths = [np.asarray(r.path) for r in plan.legs]
    print(f"plan {plan_path}: {plan.planner} on {plan.problem}, {len(paths)} leg(s), "
          f"{sum(len(p) for p in paths)} path states")  # fmt: skip
    print(f"machine: {platform.machine()} {platform.processor()}, python "
          f"{platform.python_version()}, {versions()}")  # fmt: skip
    wall = {}
    for timing in ("waypoints", "toppra"):
        t0 = time.perf_counter()
        ex = execute_legs(problem, paths, first_leg=plan.legs[0].leg, timing=timing)
        wall[timing] = time.perf_counter() - t0
        for e in ex:
            print(
                f"{timing:>9}: leg {e.leg}: wall {e.wall_time_s:7.2f} s, motion "
                f"{e.duration_s:7.2f} s, max track err {e.max_track_err_rad:.2e} rad, "
                f"contacts {len(e.contacts)}, executed cleanly {e.success}"
            )
    print(f"wall-time ratio waypoints / toppra: {wall['waypoints'] / wall['toppra']:.1f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
