"""From a problem's goal and start: the fraction of 200 extensions towards uniform samples
(seeded) that are free on the planner's grid (joint_step / 4) at each level of
native.rrtconnect's range ladder; each joint alone moved +-0.05 / 0.2 from the goal; the
pairs that stop short extensions from the goal.

    PYTHONPATH=. python results/fetch_pockets/extension_rates.py PROBLEM.toml [N]
"""
import sys, numpy as np
from plannerlab.problem.load import parse_problem
from plannerlab.collision.fcl_checker import problem_checker
p = parse_problem(sys.argv[1]); r = p.robot; ck = problem_checker(p)
g = np.asarray(p.goal(0).q_rad, float); s0 = np.asarray(p.q_start, float)
rng = np.random.default_rng(0)
N = int(sys.argv[2]) if len(sys.argv) > 2 else 200
U = rng.uniform(r.lower, r.upper, (N, r.dof))
ext = np.sqrt(np.sum((np.asarray(r.upper) - np.asarray(r.lower))**2)); R0 = 0.2 * ext
print(p.name, "range0", round(R0, 3), "goal", np.round(g, 3))
for label, q in (("goal", g), ("start", s0)):
    row = []
    for lv in range(5):
        R = R0 / 2**lv; ok = 0; first = []
        for u in U:
            d = u - q; n = np.linalg.norm(d); qb = q + d * min(1, R / n)
            _, bad = ck.check_edge(q, qb, p.joint_step / 4)
            ok += bad is None
        row.append(ok / N)
    print(label, "free fraction toward uniform samples per ladder level", row)
# which joints matter: perturb one joint at a time +-0.1
for label, q in (("goal", g),):
    for i, nm in enumerate(r.joint_names):
        res = []
        for sgn in (-1, 1):
            for a in (0.05, 0.2):
                qb = q.copy(); qb[i] = np.clip(qb[i] + sgn * a, r.lower[i], r.upper[i])
                _, bad = ck.check_edge(q, qb, p.joint_step / 4); res.append('.' if bad is None else 'x')
        print(f"  {nm:22s} -0.05 -0.2 +0.05 +0.2: {''.join(res)}")
print("goal colliding pairs at small perturbations:")
from collections import Counter
c = Counter()
for u in U[:100]:
    d = u - g; qb = g + d * (R0/16) / np.linalg.norm(d)
    ok, bad = ck.check_edge(g, qb, p.joint_step / 4)
    if bad is not None:
        qq = g + (qb - g) * 1.0
        for a, b in ck.colliding_pairs(qb): c[(a.split('#')[0], b.split('#')[0])] += 1
print(c.most_common(8))
