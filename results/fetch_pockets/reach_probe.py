"""The Fetch's reach bounds per joint (collision/reach.py: the bound used, the capsules' and
the bodies' chain sums) against the fastest capsule point seen on 200 seeded states, and
the checker's metric edge weights (None with the imported problems' margin 0).

    PYTHONPATH=. python results/fetch_pockets/reach_probe.py PROBLEM.toml
"""
import sys, numpy as np
from plannerlab.problem.load import parse_problem
from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.collision.reach import capsule_reach_bounds, body_reach_bounds, reach_bounds
p = parse_problem(sys.argv[1])
r = p.robot
print("dof", r.dof, r.joint_names, "lower", np.round(r.lower,3), "upper", np.round(r.upper,3), "cont", r.continuous)
print("joint_step", p.joint_step, "margin", p.safety_margin_m)
reach, W, rigid = reach_bounds(r)
cr, cW, _ = capsule_reach_bounds(r)
br, bW = body_reach_bounds(r)
print("capsules", len(r.link_radii_m))
print("reach used ", np.round(reach,3)); print("capsule sum", np.round(cr,3)); print("body sum   ", np.round(br,3)); print("rigid", rigid)
# seen
h=1e-6
Q = np.random.default_rng(1).uniform(np.where(r.continuous,-np.pi,r.lower), np.where(r.continuous,np.pi,r.upper), (200, r.dof))
S = np.asarray(r.link_segments(Q)); radii=np.asarray(r.link_radii_m)
seen=np.zeros(r.dof); seenW=np.zeros((r.dof,len(radii)))
for i in range(r.dof):
    Qh=Q.copy(); Qh[:,i]+=h
    sp=np.linalg.norm((np.asarray(r.link_segments(Qh))-S)/h,axis=-1).max(axis=-1)
    v=(sp+radii[None]*(sp>1e-9)).max(axis=0); seenW[i]=v; seen[i]=v.max()
print("seen       ", np.round(seen,3))
m = W>0
ratio = np.where(m, W/np.maximum(seenW,1e-9), np.nan)
print("per-capsule W/seen median per joint", np.round(np.nanmedian(ratio,axis=1),2), "max", np.round(np.nanmax(ratio,axis=1),2))
ck = problem_checker(p)
print("checker edge_weights", ck.edge_weights, "backend", ck.backend, "edge_check", ck.edge_check)
