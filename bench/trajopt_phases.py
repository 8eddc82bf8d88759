"""Where ``trajopt.rrtconnect``'s leg time goes on MotionBenchMaker's Panda, beside
``native.rrtconnect`` on the same problems (issue 34): the seed (``native.rrtconnect`` as
a sub-solve), the geometry set-up (the sphere field), the optimiser (of which the
hinge kernel), the re-check. Each phase is timed by wrapping its function; every other
figure is the leg's ``time_s``. Prints one line per problem and the medians.

Run::

    PYTHONPATH=. .venv/bin/python bench/trajopt_phases.py /tmp/mbm ['{"coarse_factor": 1}']
        [--per-scenario 20] [--every 5]   # problems 1, 6, 11, 16 of each scenario
"""

from __future__ import annotations

import argparse
import json
import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import time
from pathlib import Path
from typing import Any

import numpy as np

SCENARIOS = ("bookshelf_small", "box", "cage")
PHASES = ("seed", "geometry", "optimise", "hinge", "recheck")


def timed(obj: Any, name: str, key: str, into: dict[str, float]) -> None:
    """Wrap ``obj.name`` so that its time is added to ``into[key]``."""
    f = getattr(obj, name)

    def g(*a: Any, **k: Any) -> Any:
        t0 = time.perf_counter()
        try:
            return f(*a, **k)
        finally:
            into[key] = into.get(key, 0.0) + time.perf_counter() - t0

    setattr(obj, name, g)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("folder", type=Path)
    ap.add_argument("overrides", nargs="?", default="{}", help="trajopt settings (JSON)")
    ap.add_argument("--per-scenario", type=int, default=20)
    ap.add_argument("--every", type=int, default=5)
    args = ap.parse_args()
    import plannerlab.planners.trajopt.geometry as geometry
    import plannerlab.planners.trajopt.planner as planner
    from plannerlab.planners import make_planner
    from plannerlab.problem.load import Budget, parse_problem

    T: dict[str, float] = {}
    timed(geometry.PathGeometry, "__init__", "geometry", T)
    timed(geometry.PathGeometry, "hinge", "hinge", T)
    timed(planner, "planner_seed", "seed", T)
    timed(planner, "optimise", "optimise", T)
    timed(planner._Solve, "recheck", "recheck", T)
    files: list[Path] = []
    for s in SCENARIOS:
        files += sorted(args.folder.glob(f"{s}_[0-9]*.toml"))[: args.per_scenario : args.every]
    problems = [parse_problem(f) for f in files]
    budget = Budget(time_limit_s=10.0)
    native = make_planner("native.rrtconnect")
    trajopt = make_planner("trajopt.rrtconnect", json.loads(args.overrides))
    for p in (native, trajopt):  # untimed warm-up (compiled kernels)
        p.solve(problems[0], 0, budget, np.random.default_rng(10**6))
    print(f"overrides {args.overrides}; load average {os.getloadavg()[0]:.1f}")
    rows = []
    for i, p in enumerate(problems):
        rn = native.solve(p, 0, budget, np.random.default_rng(i))
        T.clear()
        r = trajopt.solve(p, 0, budget, np.random.default_rng(i))
        row = {"native": rn.time_s, "leg": r.time_s, **{k: T.get(k, 0.0) for k in PHASES}}
        rows.append(row)
        e = r.extra
        print(
            f"{p.name}: {r.status.value}, "
            + ", ".join(f"{k} {v * 1e3:.1f} ms" for k, v in row.items())
            + f", evaluations {r.iterations}, waypoints {e.get('first_pass_waypoints')}"
            f" -> {e.get('waypoints')}, optimised {e.get('optimised')}",
            flush=True,
        )
    med = {k: float(np.median([r[k] for r in rows])) for k in rows[0]}
    ratio = float(np.median([r["leg"] / r["native"] for r in rows]))
    print(
        f"medians over {len(rows)}: "
        + ", ".join(f"{k} {v * 1e3:.1f} ms" for k, v in med.items())
        + f"; median of leg / native {ratio:.2f}; load average {os.getloadavg()[0]:.1f}"
    )


if __name__ == "__main__":
    main()
