"""Why a leg stalls: the closest pairs at the stall state and whether the plain step is refused as not spacious. Usage (repo root, after solve_variant.py NAME): python results/variants/diag_stall.py NAME"""
import sys, numpy as np
import plannerlab as pl
from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.planners.clearance import ClearanceField
from plannerlab.planners.gradient_clearance import ClearanceDescent, ClearanceSettings
from plannerlab.robots.base import wrap_to_pi
from plannerlab.problem.goals import GoalRegion
name = sys.argv[1]
p = pl.load_problem(f"problems/variants/{name}.toml")
paths = np.load(f"/tmp/D/{name}_paths.npy", allow_pickle=True)
leave = np.asarray(paths[-1], dtype=float)
q = leave[-1]
ck = CollisionChecker(p.robot, p.scene)
pd = ck.pair_distances(q, 0.1)
names = p.scene.names
for i in np.argsort(pd.d_m)[:8]:
    o = f"module_{pd.other[i]}" if pd.other_is_link[i] else names[pd.other[i]]
    print(f"module_{pd.link[i]} - {o}: {pd.d_m[i]*100:.2f} cm t={pd.t_link[i]:.2f}")
s = ClearanceSettings(escape="detour")
field = ClearanceField(p.robot, p.scene, s.influence_m)
c = field(q)
print("field min dist", np.min(c.distances_m), "cost", c.cost)
g = p.goal(len(p.goals)-1)
sub = GoalRegion("approach", g.p_world_m - 2.5*g.n_world, g.n_world, 0.5, 30)
D = ClearanceDescent("x", s)
direction, F = D._direction(p.robot, sub, field, q)
print("tip", p.robot.tip(q)[0], "sub target", sub.p_world_m)
d_now = c.distances_m
for r in [0.01, 0.001, 1e-4]:
    step = direction * min(1.0, r/np.max(np.abs(direction)))
    qn = wrap_to_pi(q+step, p.robot.continuous)
    cn = field(qn)
    Fn = D._f(p.robot, sub, qn) + s.clearance_weight*cn.cost
    dn = cn.distances_m
    bad = ~((dn >= s.clearance_floor_m) | (dn >= d_now - 1e-9))
    print(r, "F", F, Fn, "spacious", not bad.any(), "n bad", bad.sum(), "min d_new", dn[bad].min() if bad.any() else None, "valid", ck.is_valid(qn))
