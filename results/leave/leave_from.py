"""Plan one leg of room variants from the witness state of the goal before it, per planner
(issue 33: leaving from a far corner): the leave leg by default, from the last goal's
witness (B or D on the far-ended variants).

    python results/leave/leave_from.py OUT.jsonl PLANNERS PROBLEM... [--leg NAME]
        [--seeds 0,1,2] [--checks N] [--time S] [--iterations N]

Appends one JSON line per (problem, planner, seed) to OUT.jsonl and prints it: status,
reason, collision checks, planning time, the process's CPU time of the solve, and the
leader's log (``native.rrtconnect+leader``) or the escapes (the clearance family).
Budgets per leg: iterations lifted by default, ``--time`` 30 s, ``--checks`` none.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from plannerlab.planners import make_planner  # noqa: E402
from plannerlab.problem.catalog import load_problem  # noqa: E402
from plannerlab.problem.load import Budget  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("out")
    ap.add_argument("planners")
    ap.add_argument("problems", nargs="+")
    ap.add_argument("--leg", default="leave")
    ap.add_argument("--seeds", default="0")
    ap.add_argument("--time", type=float, default=30.0)
    ap.add_argument("--checks", type=int, default=None)
    ap.add_argument("--iterations", type=int, default=100_000_000)
    a = ap.parse_args()
    for path in a.problems:
        problem = load_problem(path)
        names = [g.name for g in problem.goals]
        leg = names.index(a.leg)
        witness = problem.extras["witness"]["goal_states_rad"]
        q0 = np.array(witness[leg - 1], dtype=float) if leg > 0 else problem.q_start
        for name in a.planners.split(","):
            for seed in (int(s) for s in a.seeds.split(",")):
                planner = make_planner(name)
                budget = Budget(
                    max_iterations=a.iterations, max_collision_checks=a.checks, time_limit_s=a.time
                )
                planner.warm_up(problem, leg, q0)
                cpu = time.process_time()
                r = planner.solve(problem, leg, budget, np.random.default_rng(seed), q_start=q0)
                rec = {
                    "problem": problem.name,
                    "planner": name,
                    "seed": seed,
                    "leg": a.leg,
                    "status": r.status.value,
                    "checks": r.collision_checks,
                    "time_s": round(r.time_s, 2),
                    "cpu_s": round(time.process_time() - cpu, 2),
                    "reason": r.reason[:300],
                    "leader": r.extra.get("leader"),
                    "escapes": r.extra.get("escapes"),
                }
                print(
                    json.dumps({k: rec[k] for k in list(rec)[:8]}), rec["reason"][:160], flush=True
                )
                with open(a.out, "a") as f:
                    f.write(json.dumps(rec, default=str) + "\n")


if __name__ == "__main__":
    main()
