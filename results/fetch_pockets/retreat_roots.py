"""Emulate 'seed the goal tree with a Cartesian retreat chain': the goal pool = the goal + the
states of the longest free straight tip retreat (world axes, tip normal held, 1 cm steps, <= 30 cm),
each a root of the goal tree. A path ending at chain state k is completed by the chain (checked
on the grid when built). Same seeds and budget as settings_trials.py.

    PYTHONPATH=. python results/fetch_pockets/retreat_roots.py rows.jsonl DIR/*.toml
"""
import json, sys, time
from pathlib import Path
import numpy as np
from plannerlab.planners import make_planner
from plannerlab.planners.native import solve as NS
from plannerlab.problem.load import parse_problem
from plannerlab.problem.settings import Budget
from plannerlab.collision.fcl_checker import problem_checker
DIRS = np.vstack([np.eye(3), -np.eye(3)])
def chain(P, ck):
    r = P.robot; g = np.asarray(P.goal(0).q_rad, float); best = [g]
    for d in DIRS:
        q = g.copy(); p0, n0 = r.tip(q); states = [g]
        for k in range(30):
            Jp, Jn = r.tip_jacobian(q); pt, n = r.tip(q)
            J = np.vstack([Jp, Jn]); e = np.concatenate([p0 + d * 0.01 * (k + 1) - pt, n0 - n])
            qn = np.clip(q + J.T @ np.linalg.solve(J @ J.T + 1e-3 * np.eye(6), e), r.lower, r.upper)
            if ck.check_edge(q, qn, P.joint_step / 4)[1] is not None: break
            q = qn; states.append(q)
        if len(states) > len(best): best = states
    return np.array(best)
orig = NS.NativeSolve.goal_pool
CH = {}
def goal_pool(self):
    G, failed = orig(self)
    if failed is None and "chain" in CH:
        G = np.vstack([G, CH["chain"][1:]])
    return G, failed
NS.NativeSolve.goal_pool = goal_pool
out = Path(sys.argv[1]); files = sys.argv[2:]
with out.open("a") as log:
    for f in files:
        P = parse_problem(f); ck = problem_checker(P); c0 = ck.checks
        t0 = time.process_time(); CH["chain"] = chain(P, ck); tc = time.process_time() - t0
        pl = make_planner("native.rrtconnect", {})
        for seed in (0, 1):
            c1 = time.process_time()
            r = pl.solve(P, 0, Budget(time_limit_s=10, max_collision_checks=1500000, clock=time.process_time), np.random.default_rng(1000 + seed))
            end = r.path[-1] if len(r.path) else None
            k = int(np.argmin(np.linalg.norm(CH["chain"] - end, axis=1))) if end is not None else -1
            rec = dict(config="retreat_roots", name=P.name, seed=seed, status=r.status.name, checks=r.collision_checks,
                       cpu_s=time.process_time() - c1, chain_len=len(CH["chain"]), chain_checks=ck.checks - c0, chain_cpu_s=tc,
                       ends_at_chain_state=k, nodes=r.extra.get("nodes"), reason=r.reason[:120])
            log.write(json.dumps(rec) + "\n"); log.flush(); print(rec, flush=True)
