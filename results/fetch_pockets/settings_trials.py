"""native.rrtconnect with setting overrides on a few problems x seeds (seed 1000 + s), a CPU-time
limit and optionally a check budget; one JSON line each (resumable).

    PYTHONPATH=. python results/fetch_pockets/settings_trials.py DIR/*.toml \\
        --config 'default={}' --config 'dd={"dynamic_domain":true}' --seeds 0,1 \\
        --checks 1500000 --cpu 10 --out rows.jsonl

(the connect_on trial needs the code of 9a0145d.)
"""
import argparse, json, sys, time
from pathlib import Path
import numpy as np
from plannerlab.planners import make_planner
from plannerlab.problem.load import parse_problem
from plannerlab.problem.settings import Budget
ap = argparse.ArgumentParser()
ap.add_argument("files", nargs="+", type=Path)
ap.add_argument("--config", action="append", default=[], help="NAME=JSON overrides")
ap.add_argument("--seeds", default="0,1")
ap.add_argument("--cpu", type=float, default=10.0)
ap.add_argument("--checks", type=int, default=None)
ap.add_argument("--planner", default="native.rrtconnect")
ap.add_argument("--out", type=Path, required=True)
a = ap.parse_args()
done = set()
if a.out.is_file():
    for s in a.out.read_text().splitlines():
        r = json.loads(s); done.add((r["config"], r["name"], r["seed"]))
configs = [c.split("=", 1) for c in a.config] or [["default", "{}"]]
with a.out.open("a") as log:
    for f in a.files:
        p = parse_problem(f)
        for name, js in configs:
            planner = make_planner(a.planner, json.loads(js))
            for seed in map(int, a.seeds.split(",")):
                if (name, p.name, seed) in done: continue
                b = Budget(time_limit_s=a.cpu, max_collision_checks=a.checks, clock=time.process_time)
                c0 = time.process_time()
                r = planner.solve(p, 0, b, np.random.default_rng(1000 + seed))
                cpu = time.process_time() - c0
                rec = dict(config=name, name=p.name, seed=seed, status=r.status.name, cpu_s=cpu,
                           checks=r.collision_checks, iterations=r.iterations,
                           **{k: r.extra[k] for k in ("nodes", "restarts", "planning_checks") if k in r.extra})
                log.write(json.dumps(rec) + "\n"); log.flush()
                print(rec, flush=True)
