"""What executing a plan costs against its motion's duration, per leg: wall and CPU time
of each leg's execution (``plannerlab.sim.execute._run``: re-check, retiming, PyBullet's
steps, the deviation and the clearance probe), against the simulated time (the motion
and 1 s of settling) (issue 35, item 6: at most 3x; ``results/mesh_robots.md``).

    PYTHONPATH=. nice -n 10 .venv/bin/python bench/execute_cost.py PLAN.json [--repeats 2] \\
        [--variants before,after]

``before``: ``UrdfChain.link_segments`` as it was up to ``f4d11dc`` (a 4x4 frame gathered
per capsule and state, ``einsum``; kept here as the reference), ``after``: the code as it
is; the variants alternate within one run, so they share the load.

On a loaded machine the wall time measures the load (a ``nice`` process on 2 shared cores
gets a fraction of one): the CPU time of the process is the figure to compare; the load
average is printed with it. The first repeat's first leg holds the one-off imports
(TOPP-RA, ...).
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import sys
import time
from pathlib import Path
from typing import Any


def link_segments_before(self: Any, q: Any) -> Any:
    """``UrdfChain.link_segments`` up to ``f4d11dc``."""
    import numpy as np

    B = self._bodies(q)
    Fb = B[..., self._cap_body, :, :]
    R, t = Fb[..., :3, :3], Fb[..., :3, 3]
    a = np.einsum("...lij,lj->...li", R, self._cap_a) + t
    b = np.einsum("...lij,lj->...li", R, self._cap_b) + t
    return np.stack([a, b], axis=-2)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("plan", type=Path)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--variants", default="after")
    args = ap.parse_args()
    import plannerlab as pl
    from plannerlab.record.plan import Plan
    from plannerlab.robots.urdf.model import UrdfChain

    ex_mod = importlib.import_module("plannerlab.sim.execute")

    link_segments_after = UrdfChain.link_segments

    plan = Plan.load(args.plan)
    problem = plan.load_problem()
    cpu: list[float] = []
    inner = ex_mod._run

    def timed(*a: Any, **k: Any) -> Any:
        c0 = time.process_time()
        out = inner(*a, **k)
        cpu.append(time.process_time() - c0)
        return out

    ex_mod._run = timed
    runs = [(r, v) for r in range(args.repeats) for v in args.variants.split(",")]
    for r, variant in runs:
        UrdfChain.link_segments = (  # type: ignore[method-assign]
            link_segments_before if variant == "before" else link_segments_after
        )
        cpu.clear()
        load0 = os.getloadavg()[0]
        c0, t0 = time.process_time(), time.perf_counter()
        execs = pl.execute(plan, problem)
        total_cpu, total_wall = time.process_time() - c0, time.perf_counter() - t0
        for e, c in zip(execs, cpu, strict=True):
            print(
                json.dumps(
                    {
                        "repeat": r,
                        "variant": variant,
                        "leg": e.leg,
                        "motion_s": round(e.sim_time_s, 2),
                        "wall_s": round(e.wall_time_s, 2),
                        "cpu_s": round(c, 2),
                        "wall_ratio": round(e.wall_time_s / e.sim_time_s, 2),
                        "cpu_ratio": round(c / e.sim_time_s, 2),
                        "clean": bool(e.success),
                        "clearance_samples": e.clearance_samples,
                        "max_deviation_mm": round(e.max_deviation_m * 1e3, 3),
                        "min_clearance_mm": round(e.min_clearance_m * 1e3, 2),
                    }
                ),
                flush=True,
            )
        print(
            json.dumps(
                {
                    "repeat": r,
                    "variant": variant,
                    "execute_wall_s": round(total_wall, 2),
                    "execute_cpu_s": round(total_cpu, 2),
                    "load": [round(load0, 2), round(os.getloadavg()[0], 2)],
                }
            ),
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
