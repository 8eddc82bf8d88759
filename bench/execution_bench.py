"""What each execution option buys: deviation per leg, clearance, verdict and wall time.

Usage (plans are made first, on a fixed seed and collision-check budget):

    PYTHONPATH=. python bench/execution_bench.py                 # solves the default plan
    PYTHONPATH=. python bench/execution_bench.py PLAN.json ...   # any plan files
    PYTHONPATH=. python bench/execution_bench.py --options chosen,pgs PLAN.json
    PYTHONPATH=. python bench/execution_bench.py --baseline-checkout DIR --rounds 3 PLAN.json

The default plan is the paper's task: ``plannerlab solve armz_inspection --planner
gradient.clearance+detour --seed 0 --max-checks 100000`` (seven legs). Every option
executes the same legs of every plan in this process, one after the other
(:func:`plannerlab.sim.execute.execute_legs`, the legs in one world as ``compare
--execute`` runs them); the script prints, per option, each leg's largest deviation of
the collision geometry from the commanded state [mm], the smallest simulated clearance
[mm], the verdict, and the option's wall time as a ratio to the first option's (``today``
by default: PyBullet's iterative solver and TOPP-RA's grid at the knots, the executor's
settings before issue 17, measured with today's deviation and clearance measurement, so
both sides pay for it). ``--baseline-checkout DIR`` also times the executor of another
checkout (e.g. the main branch) on the same plans, in a subprocess, between the options,
and prints the ratios to it: the machine is shared and noisy, so only ratios measured in
one run mean anything; ``--rounds N`` repeats everything and prints the median of the
per-round ratios. (A checkout is best an exported copy, ``git archive COMMIT | tar -x -C
DIR``: running it writes caches into it.)

Options (name: settings of ``execute_legs``):

* ``today``: solver "pgs", grid_per_knot 1;
* ``pgs200``: solver "pgs" with 200 iterations, grid_per_knot 1;
* ``dt/4``: solver "pgs", dt_s = 1/960, grid_per_knot 1;
* ``dantzig``: solver "dantzig", grid_per_knot 1;
* ``grid4``: solver "pgs", grid_per_knot 4;
* ``grid2+dantzig``: solver "dantzig", grid_per_knot 2;
* ``spline``: the defaults, with the natural cubic spline reference of before the PCHIP
  (its deviation, measured against the plan, holds the spline's distance from it);
* ``chosen``: the defaults (solver "dantzig", grid_per_knot 4, the PCHIP reference).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

OPTIONS: dict[str, dict[str, Any]] = {
    "today": {"solver": "pgs", "grid_per_knot": 1},
    "pgs200": {"solver": "pgs", "solver_iterations": 200, "grid_per_knot": 1},
    "dt/4": {"solver": "pgs", "dt_s": 1.0 / 960.0, "grid_per_knot": 1},
    "dantzig": {"solver": "dantzig", "grid_per_knot": 1},
    "grid4": {"solver": "pgs", "grid_per_knot": 4},
    "grid2+dantzig": {"solver": "dantzig", "grid_per_knot": 2},
    "spline": {"interpolant": "spline"},
    "chosen": {},
}

_BASELINE = """
import json, sys, time
import numpy as np
from plannerlab.record.plan import Plan
from plannerlab.sim.execute import execute_legs
out = []
for f in sys.argv[1:]:
    plan = Plan.load(f)
    problem = plan.load_problem()
    paths = [np.asarray(r.path) for r in plan.legs if r.path is not None and len(r.path)]
    t0 = time.perf_counter()
    ex = execute_legs(problem, paths, first_leg=plan.legs[0].leg)
    wall = time.perf_counter() - t0
    out.append({"plan": f, "wall_s": wall, "sim_s": sum(e.sim_time_s for e in ex),
                "tip_mm": [1e3 * e.max_tip_track_err_m for e in ex],
                "clean": [e.success for e in ex]})
print("BASELINE " + json.dumps(out))
"""


def _baseline(checkout: Path, plans: list[Path]) -> list[dict[str, Any]]:
    env = dict(os.environ, PYTHONPATH=str(checkout))
    proc = subprocess.run(
        [sys.executable, "-c", _BASELINE, *map(str, plans)],
        env=env,
        capture_output=True,
        text=True,
        check=True,
        cwd=str(checkout),
    )
    line = [ln for ln in proc.stdout.splitlines() if ln.startswith("BASELINE ")][-1]
    result: list[dict[str, Any]] = json.loads(line[len("BASELINE ") :])
    return result


def main(argv: list[str]) -> int:
    from plannerlab.record.files import versions
    from plannerlab.record.plan import Plan
    from plannerlab.sim.execute import execute_legs

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("plans", nargs="*", type=Path)
    ap.add_argument("--options", default=",".join(OPTIONS), help="comma-separated names")
    ap.add_argument("--baseline-checkout", type=Path, default=None)
    ap.add_argument("--rounds", type=int, default=1, help="repeat everything, ratios per round")
    args = ap.parse_args(argv)
    names = [n for n in args.options.split(",") if n]
    unknown = [n for n in names if n not in OPTIONS]
    if unknown:
        print(f"unknown options {unknown}; known: {', '.join(OPTIONS)}", file=sys.stderr)
        return 2

    plans = list(args.plans)
    if not plans:
        plan_path = Path(tempfile.mkdtemp(prefix="plannerlab_exec_bench_")) / "plan.json"
        cmd = [
            sys.executable, "-m", "plannerlab", "solve", "armz_inspection",
            "--planner", "gradient.clearance+detour", "--seed", "0",
            "--max-checks", "100000", "--out", str(plan_path),
        ]  # fmt: skip
        print("$", " ".join(cmd[1:]))
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        plans = [plan_path]
    loaded = []
    for f in plans:
        plan = Plan.load(f)
        problem = plan.load_problem()
        paths = [np.asarray(r.path) for r in plan.legs if r.path is not None and len(r.path)]
        loaded.append((f, plan, problem, paths))
        print(f"plan {f}: {plan.planner} on {plan.problem}, {len(paths)} leg(s)")
    print(
        f"machine: {platform.machine()} {platform.processor()}, {os.cpu_count()} cores, "
        f"load {os.getloadavg()[0]:.1f}, python {platform.python_version()}, {versions()}"
    )

    # warm-up: imports, the compiled core, toppra
    f0, _, problem0, paths0 = loaded[0]
    execute_legs(problem0, [paths0[0][:2]], first_leg=0)

    walls: dict[str, list[float]] = {n: [] for n in names}
    base_wall: list[float] = []
    for round_ in range(args.rounds):
        if args.rounds > 1:
            print(f"-- round {round_ + 1} of {args.rounds}")
        for i, name in enumerate(names):
            if args.baseline_checkout is not None and i == len(names) // 2:
                base = _baseline(args.baseline_checkout, [p[0] for p in loaded])
                base_wall.append(sum(b["wall_s"] for b in base))
                for b in base:
                    tips = " ".join(f"{t:6.1f}" for t in b["tip_mm"])
                    print(
                        f"{'checkout':>14} {Path(b['plan']).name}: wall {b['wall_s']:6.1f} s, "
                        f"simulated {b['sim_s']:6.1f} s, tip mm [{tips}], clean {b['clean']}",
                        flush=True,
                    )
            wall = 0.0
            for f, plan, problem, paths in loaded:
                t0 = time.perf_counter()
                ex = execute_legs(problem, paths, first_leg=plan.legs[0].leg, **OPTIONS[name])
                w = time.perf_counter() - t0
                wall += w
                devs = " ".join(f"{1e3 * e.max_deviation_m:7.2f}" for e in ex)
                clears = " ".join(f"{1e3 * e.min_clearance_m:6.1f}" for e in ex)
                print(
                    f"{name:>14} {f.name}: wall {w:6.1f} s, simulated "
                    f"{sum(e.sim_time_s for e in ex):6.1f} s, deviation mm [{devs}], "
                    f"clearance mm [{clears}], clean {[e.success for e in ex]}",
                    flush=True,
                )
            walls[name].append(wall)
    first = names[0]
    print(
        f"\nwall-time ratio to {first!r}"
        + (" and to the checkout" if base_wall else "")
        + (
            f" (median over {args.rounds} rounds, each ratio within its round)"
            if args.rounds > 1
            else ""
        )
    )
    for name in names:
        total = float(np.median(walls[name]))
        line = f"{name:>14}: {total:7.1f} s  "
        line += f"{np.median(np.divide(walls[name], walls[first])):5.2f}x"
        if base_wall:
            line += f"  {np.median(np.divide(walls[name], base_wall)):5.2f}x"
        print(line)
    if base_wall:
        print(f"{'checkout':>14}: {float(np.median(base_wall)):7.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
