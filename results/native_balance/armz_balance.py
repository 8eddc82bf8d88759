"""native.rrtconnect with the trees in turn (OMPL's) against the balanced trees, on
problems by name, a seed range and a planner; one JSON line per problem and setting:
solved seeds, median and mean collision checks, mean CPU seconds of a solve. Each leg is
solved from its own start (1 000 000 checks, 60 s as a guard).

    PYTHONPATH=. python results/native_balance/armz_balance.py \\
        armz_pocket,armz_window,armz_cavity,armz_thin_wall,armz_deep_e,irb6_track_obstacle \\
        5 native.rrtconnect
"""

import json
import sys
import time

import numpy as np

from plannerlab.planners import make_planner
from plannerlab.problem.catalog import load_problem
from plannerlab.problem.load import Budget

names = sys.argv[1].split(",")
seeds = range(int(sys.argv[2]))
planner = sys.argv[3]
for n in names:
    p = load_problem(n)
    for name, ov in (("turns", {"balance": False}), ("balance", {"balance": True})):
        pl = make_planner(planner, ov)
        solved, checks, cpu = 0, [], []
        for seed in seeds:
            t = time.process_time()
            ok, c = True, 0
            for leg in range(p.legs):
                budget = Budget(max_collision_checks=1_000_000, time_limit_s=60)
                r = pl.solve(p, leg, budget, np.random.default_rng(seed))
                c += r.collision_checks
                if r.status.name != "SOLVED":
                    ok = False
                    break
            solved += ok
            checks.append(c)
            cpu.append(time.process_time() - t)
        row = dict(problem=n, planner=planner, variant=name, solved=solved, n=len(seeds))
        row |= dict(median_checks=float(np.median(checks)), mean_checks=float(np.mean(checks)))
        print(json.dumps(row | dict(mean_cpu=round(float(np.mean(cpu)), 3))), flush=True)
