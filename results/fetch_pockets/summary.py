"""Solved / valid, CPU and planning times of the solved, failures by scenario, goal-tree
sizes and checks per CPU second of the failures, invalid goals: one log of
bench/mbm_robots_bench.py.

    python results/fetch_pockets/summary.py LOG.jsonl
"""
import json, sys, collections, numpy as np
rows = [json.loads(s) for s in open(sys.argv[1])]
valid = [r for r in rows if r['status'] not in ('INVALID_GOAL', 'INVALID_START')]
ok = [r for r in valid if r['solved']]
print(f"{len(rows)} logged, {len(valid)} valid, solved {len(ok)} ({100*len(ok)/len(valid):.1f} %)")
cpu = np.array([r['cpu_s'] for r in ok]); pl = np.array([r['plan_s'] for r in ok])
print(f"solved: CPU median {np.median(cpu):.3f} s p95 {np.percentile(cpu,95):.2f} s; plan_s median {np.median(pl)*1e3:.1f} ms p95 {np.percentile(pl,95):.2f} s")
fail = [r for r in valid if not r['solved']]
by = collections.Counter(r['name'].rsplit('_',1)[0] for r in fail)
print("failures by scenario", dict(by))
print("failure statuses", collections.Counter(r['status'] for r in fail))
n = np.array([r['nodes'] for r in fail if r.get('nodes')])
ck = np.array([r['checks']/r['cpu_s'] for r in fail])
print(f"failed: goal-tree nodes median {np.median(n[:,1]):.0f} (min {n[:,1].min()}, max {n[:,1].max()}); checks/CPU-s median {np.median(ck)/1e3:.0f} k ({ck.min()/1e3:.0f}-{ck.max()/1e3:.0f} k)")
print("invalid:", [(r['name'], r['reason'][:70]) for r in rows if r['status'].startswith('INVALID')])
