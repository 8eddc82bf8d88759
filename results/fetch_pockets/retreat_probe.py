"""From each problem's goal: how far the tip can retreat in a straight line along each world
axis (tip normal held; damped least squares on the tip Jacobian; 1 cm steps, each edge
checked on the grid at joint_step / 4; at most 30 cm), and the clearance where it stops.

    PYTHONPATH=. python results/fetch_pockets/retreat_probe.py PROBLEM.toml ...
"""
import sys, numpy as np
from plannerlab.problem.load import parse_problem
from plannerlab.collision.fcl_checker import problem_checker
DIRS = np.vstack([np.eye(3), -np.eye(3)])
for f in sys.argv[1:]:
    P = parse_problem(f); r = P.robot; ck = problem_checker(P)
    g = np.asarray(P.goal(0).q_rad, float)
    res = []
    for d in DIRS:
        q = g.copy(); p0, n0 = r.tip(q); dist = 0.0; clr = 1e3*ck.clearance(q); checks0 = ck.checks
        for k in range(30):
            Jp, Jn = r.tip_jacobian(q); pt, n = r.tip(q)
            J = np.vstack([Jp, Jn]); e = np.concatenate([p0 + d * 0.01 * (k + 1) - pt, n0 - n])
            dq = J.T @ np.linalg.solve(J @ J.T + 1e-3 * np.eye(6), e)
            qn = np.clip(q + dq, r.lower, r.upper)
            _, bad = ck.check_edge(q, qn, P.joint_step / 4)
            if bad is not None: break
            q = qn; dist = 0.01 * (k + 1); clr = 1e3 * ck.clearance(q)
        res.append(f"{''.join('+-'[int(x<0)] + 'xyz'[i] for i,x in enumerate(d) if x)}:{dist:.2f}m/{clr:.0f}mm")
    print(P.name, " ".join(res))
