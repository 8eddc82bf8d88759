"""Goal tree alone, short steps: nearest-node (RRT's Voronoi bias) vs a random node of the tree
extended towards a uniform sample. Counts nodes added and how far the tip got from the goal."""
import sys, numpy as np
from plannerlab.problem.load import parse_problem
from plannerlab.collision.fcl_checker import problem_checker
P = parse_problem(sys.argv[1]); r = P.robot; ck = problem_checker(P)
g = np.asarray(P.goal(0).q_rad, float); tip0 = r.tip(g)[0]
lo, hi = np.asarray(r.lower), np.asarray(r.upper)
step = float(sys.argv[2]); N = int(sys.argv[3])
for mode in ("nearest", "random_node"):
    rng = np.random.default_rng(0); Q = [g]; ok = 0; c0 = ck.checks
    for it in range(N):
        u = rng.uniform(lo, hi)
        A = np.array(Q)
        i = int(np.argmin(((A - u) ** 2).sum(1))) if mode == "nearest" else int(rng.integers(len(Q)))
        d = u - A[i]; qb = A[i] + d * min(1.0, step / np.linalg.norm(d))
        _, bad = ck.check_edge(A[i], qb, P.joint_step / 4)
        if bad is None: Q.append(qb); ok += 1
    tips = r.tip(np.array(Q))[0]; far = np.linalg.norm(tips - tip0, axis=1).max()
    clr = max(ck.clearance(q) for q in Q[-50:]) * 1e3
    print(f"{P.name} step {step} {mode:12s}: {ok}/{N} extensions free, tip up to {far*100:.1f} cm from the goal's, best clearance of the last 50 nodes {clr:.0f} mm")
