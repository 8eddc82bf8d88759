"""Solve legs 0..LEG of a variant, then at the last leg's final state compare the plain and the held (hold_clearance) step. Usage: python results/variants/diag_stall_fixed.py NAME LEG"""
import sys, numpy as np
import plannerlab as pl
from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.planners.clearance import ClearanceField
from plannerlab.planners.gradient_clearance import ClearanceDescent, ClearanceSettings
from plannerlab.robots.base import wrap_to_pi
from plannerlab.problem.goals import GoalRegion
name, leg = sys.argv[1], int(sys.argv[2])
p = pl.load_problem(f"problems/variants/{name}.toml")
plan = pl.solve(p, "gradient.clearance+detour", 0, legs=list(range(leg+1)), budget=p.budget.replace(max_collision_checks=100000))
r = plan.legs[-1]
print(r.goal, r.status.value, r.reason[:200], len(r.path))
q = np.asarray(r.path[-1])
ck = CollisionChecker(p.robot, p.scene)
pd = ck.pair_distances(q, 0.1)
names = p.scene.names
for i in np.argsort(pd.d_m)[:6]:
    o = f"module_{pd.other[i]}" if pd.other_is_link[i] else names[pd.other[i]]
    print(f"module_{pd.link[i]} - {o}: {pd.d_m[i]*100:.2f} cm t={pd.t_link[i]:.2f}")
s = ClearanceSettings(escape="detour")
field = ClearanceField(p.robot, p.scene, s.influence_m)
g = p.goal(leg)
sub = GoalRegion("approach", g.p_world_m - 2.5*g.n_world, g.n_world, 0.5, 30)
print("tip", p.robot.tip(q)[0], "goal", g.p_world_m, "approach", sub.p_world_m)
D = ClearanceDescent("x", s)
c = field(q); d_now = c.distances_m
direction, F = D._direction(p.robot, sub, field, q)
for label, dirn in (("plain", direction), ("held", D._hold_clearance(field, q, direction))):
  for rr in [0.01, 0.001, 1e-4]:
    step = dirn * min(1.0, rr/np.max(np.abs(dirn)))
    qn = wrap_to_pi(q+step, p.robot.continuous)
    cn = field(qn)
    Fn = D._f(p.robot, sub, qn) + s.clearance_weight*cn.cost
    dn = cn.distances_m
    bad = ~((dn >= s.clearance_floor_m) | (dn >= d_now - 1e-9))
    print(label, rr, "dF", Fn - F, "spacious", not bad.any(), "valid", ck.is_valid(qn))
