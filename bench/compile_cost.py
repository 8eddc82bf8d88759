"""What a cold numba cache costs: the CPU time numba spends compiling, per kernel, when one
planner solves one leg in a fresh process with an empty cache.

The suite's cold run (CI's) pays this once per test process; a user pays it on the first
plan after an install or an update. Each kernel's figure is its own compile time, without
the kernels it calls (those are listed under their own names).

Run (an empty cache folder of its own, so nothing is loaded from another run)::

    PYTHONPATH=. .venv/bin/python bench/compile_cost.py [--planner native.rrtconnect]
        [--problem armz_pocket] [--top 25]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from collections import Counter


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--planner", default="native.rrtconnect")
    ap.add_argument("--problem", default="armz_pocket", help="a bundled name or a TOML file")
    ap.add_argument("--checks", type=int, default=1_000_000, help="the leg's check budget")
    ap.add_argument("--top", type=int, default=25)
    args = ap.parse_args()
    if "numba" in sys.modules or "plannerlab" in sys.modules:
        raise SystemExit("run this as a script: numba must not be imported yet")
    os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="plannerlab-cold-")

    import numpy as np
    from numba.core import event

    own: Counter[str] = Counter()
    stack: list[list[float]] = []

    class Compiles(event.Listener):
        def on_start(self, e: event.Event) -> None:
            stack.append([time.process_time(), 0.0])

        def on_end(self, e: event.Event) -> None:
            t0, inner = stack.pop()
            dt = time.process_time() - t0
            if stack:
                stack[-1][1] += dt
            f = e.data["dispatcher"].py_func
            own[f"{f.__module__}.{f.__qualname__}"] += dt - inner

    event.register("numba:compile", Compiles())
    t0 = time.process_time()
    from plannerlab.planners import make_planner
    from plannerlab.problem.catalog import load_problem
    from plannerlab.problem.load import Budget

    problem = load_problem(args.problem)
    planner = make_planner(args.planner, {})
    planner.warm_up(problem, 0, problem.q_start)
    r = planner.solve(
        problem, 0, Budget(max_collision_checks=args.checks), np.random.default_rng(0)
    )
    total = time.process_time() - t0
    load = os.getloadavg()[0]
    print(f"{args.planner} on {args.problem}: {r.status.value}; load average {load:.1f}")
    print(f"CPU of the whole run {total:.1f} s, of which numba compiling {sum(own.values()):.1f} s")
    print(f"{'own compile CPU s':>18}  kernel")
    for name, s in own.most_common(args.top):
        print(f"{s:18.1f}  {name}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
