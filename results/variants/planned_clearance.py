"""Solve legs 0..LEG of a variant and print the planned clearance of one module to one obstacle on leg LEG. Usage: python results/variants/planned_clearance.py NAME LEG MODULE OBSTACLE"""
import sys, numpy as np
import plannerlab as pl
from plannerlab.collision.fcl_checker import CollisionChecker
name, upto, link, obst = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
p = pl.load_problem(f"problems/variants/{name}.toml")
plan = pl.solve(p, "gradient.clearance+detour", 0, legs=list(range(upto+1)), budget=p.budget.replace(max_collision_checks=100000))
r = plan.legs[-1]
ck = CollisionChecker(p.robot, p.scene)
oi = p.scene.names.index(obst)
from plannerlab.robots.paths import densify
best = []
for q in r.path:
    pd = ck.pair_distances(q, 1.0)
    m = (pd.link == link) & (pd.other == oi) & ~pd.other_is_link
    best.append(pd.d_m[m].min() if m.any() else np.inf)
allmin = min(ck.clearance(q) for q in r.path)
print(r.goal, r.status.value, "planned clearance of", f"module_{link}", obst, f"min {min(best)*100:.2f} cm", "leg min clearance", f"{allmin*100:.2f} cm", "states", len(r.path))
