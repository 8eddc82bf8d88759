"""v14 legs enter and A with hold_clearance projected in the Gauss-Newton metric (default)
or Euclidean (as before 370bd85). Usage: python results/variants/diag_hold_metric.py
[gauss_newton|euclidean]"""

import sys

from plannerlab.run.pipeline import solve_legs
from plannerlab.planners.gradient_clearance import ClearanceDescent
from plannerlab.problem.catalog import load_problem

overrides = {}
if sys.argv[1:] == ["euclidean"]:
    # the numpy descent (the compiled one takes its metric from its own evaluation)
    ClearanceDescent._metric = lambda self, *args: None  # type: ignore[method-assign]
    overrides = {"backend": "numpy"}
problem = load_problem("problems/variants/armz_inspection_v14.toml")
budget = problem.budget.replace(max_collision_checks=100_000, time_limit_s=None)
plan = solve_legs(
    problem, "gradient.clearance+detour", 0, legs=[0, 1], budget=budget, overrides=overrides
)
for r in plan.legs:
    print(r.goal, r.status.value, r.collision_checks, r.reason)
