"""Solve every leg of a variant (gradient.clearance+detour, seed 0, 100 000 checks per leg) and save the paths to /tmp/D/NAME_paths.npy. Usage: python results/variants/solve_variant.py NAME"""
import sys, json, numpy as np
import plannerlab as pl
from plannerlab.problem.load import Budget
name = sys.argv[1]
p = pl.load_problem(f"problems/variants/{name}.toml")
plan = pl.solve(p, "gradient.clearance+detour", 0, budget=p.budget.replace(max_collision_checks=100000))
plan.save(f"/tmp/D/{name}.plan.json") if hasattr(plan, "save") else None
for r in plan.legs:
    print(r.goal, r.status.value, r.reason[:150], len(r.path), r.extra.get("escapes"))
np.save(f"/tmp/D/{name}_paths.npy", np.array([np.asarray(r.path) for r in plan.legs], dtype=object), allow_pickle=True)
