"""What a cold numba cache costs: the CPU time numba spends compiling, per kernel, when one
planner solves one leg in a fresh process with an empty cache.

The suite's cold run (CI's) pays this once per test process; a user pays it on the first
plan after an install or an update. Each kernel's figure is its own compile time, without
the kernels it calls (those are listed under their own names).

Run (an empty cache folder of its own, so nothing is loaded from another run)::

    PYTHONPATH=. .venv/bin/python bench/compile_cost.py [--planner native.rrtconnect]
        [--problem armz_pocket] [--top 25] [--signatures]

``--signatures`` also lists every kernel compiled more than once, with the argument types
that differ between its compiles (a constant argument typed ``Literal[int](1)``, a layout
``array(float64, 1d, C)`` against ``A``, ``int32`` against ``int64``, an omitted argument).
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
    ap.add_argument(
        "--signatures", action="store_true", help="list kernels compiled more than once and why"
    )
    args = ap.parse_args()
    if "numba" in sys.modules or "plannerlab" in sys.modules:
        raise SystemExit("run this as a script: numba must not be imported yet")
    os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp(prefix="plannerlab-cold-")

    import numpy as np
    from numba.core import event

    own: Counter[str] = Counter()
    sigs: dict[str, list[tuple[tuple[object, ...], float]]] = {}
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
            name = f"{f.__module__}.{f.__qualname__}"
            own[name] += dt - inner
            sigs.setdefault(name, []).append((tuple(e.data["args"]), dt - inner))

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
    if args.signatures:
        _print_repeats(sigs)
    return 0


def _print_repeats(sigs: dict[str, list[tuple[tuple[object, ...], float]]]) -> None:
    """The kernels compiled more than once, costliest first, each compile's own CPU and
    the arguments that differ between the compiles (position: type)."""
    again = {k: v for k, v in sigs.items() if len(v) > 1}
    n_extra = sum(len(v) - 1 for v in again.values())
    extra_s = sum(sum(dt for _, dt in v) - max(dt for _, dt in v) for v in again.values())
    print(
        f"\n{len(again)} kernels compiled more than once: {n_extra} extra compiles, "
        f"{extra_s:.1f} s own CPU beyond the costliest compile of each"
    )
    order = sorted(again.items(), key=lambda kv: -sum(dt for _, dt in kv[1]))
    for name, runs in order:
        print(f"{sum(dt for _, dt in runs):6.1f} s  {len(runs)}x  {name}")
        width = max(len(a) for a, _ in runs)
        differ = [
            i
            for i in range(width)
            if len({str(a[i]) if i < len(a) else "(omitted)" for a, _ in runs}) > 1
        ]
        for a, dt in runs:
            shown = ", ".join(f"{i}: {a[i] if i < len(a) else '(omitted)'}" for i in differ)
            print(f"{dt:14.1f} s  {shown or '(same types: another dispatcher or cache miss)'}")


if __name__ == "__main__":
    raise SystemExit(main())
