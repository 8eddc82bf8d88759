"""Is a failing tip goal of ``bench/mesh_arms_bench.py`` one hard goal, or is the kind of
problem hard? The same problem made with the next valid goal states (the maker takes the
first valid state, in seeded order, whose tip lies in the goal region; here the first
``--goals`` of them), each solved by ``--planner`` with a check budget (issue 35, the
UR10 shelf; ``results/mesh_robots.md``).

    PYTHONPATH=. nice -n 10 .venv/bin/python bench/mesh_shelf_goals.py PROBLEM.toml \\
        --urdf URDF [--goals 6] [--max-checks 300000] [--seeds 0]

``--joint-goals``: each goal state itself as the goal (a joint goal: one tree root, no IK).
Per goal state: its tip's distance from the base over the arm's reach ``R`` (the maker's),
its elbow-free measure (the free-motion fraction at a quarter of the default range,
``bench/mbm_why.py``), and the leg's status, checks and tree sizes (reach leg only).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tomllib
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("problem", type=Path)
    ap.add_argument("--urdf", type=Path, required=True)
    ap.add_argument("--region", default="shelf", help="the maker's scene whose goal region")
    ap.add_argument("--goals", type=int, default=6)
    ap.add_argument("--max-checks", type=int, default=300000)
    ap.add_argument("--seeds", default="0")
    ap.add_argument("--joint-goals", action="store_true", help="each goal state as a joint goal")
    args = ap.parse_args()
    from mbm_why import free_fractions
    from mesh_arms_bench import _toml, scenes

    import plannerlab as pl
    from plannerlab.collision.fcl_checker import problem_checker
    from plannerlab.planners.native.solve import space_extent
    from plannerlab.robots.urdf.model import UrdfChain
    from plannerlab.run.robot_info import default_tip_link

    print(json.dumps({"load_start": os.getloadavg()}), flush=True)
    doc = tomllib.loads(args.problem.read_text())
    tip = default_tip_link(args.urdf)
    robot = UrdfChain(args.urdf, tip)
    rng = np.random.default_rng(0)  # the maker's states
    Q = rng.uniform(robot.lower, robot.upper, size=(20000, robot.dof))
    P, N = robot.tip(Q)
    R = float(np.max(np.linalg.norm(P, axis=1)))
    lo, hi = (np.asarray(v) for v in scenes(R)[args.region][2])
    problem = pl.load_problem(args.problem)
    checker = problem_checker(problem)
    range0 = 0.2 * space_extent(checker.model)
    found = 0
    for i in np.flatnonzero(np.all((P >= lo) & (P <= hi), axis=1)):
        if found >= args.goals:
            break
        if not checker.is_valid(Q[i]):
            continue
        found += 1
        goal = dict(doc["goals"][0])
        if args.joint_goals:  # the state itself as the goal
            goal = {"name": goal["name"], "q": Q[i].round(6).tolist(), "joint_tol_rad": 0.001}
        else:
            goal["p_m"] = P[i].round(5).tolist()
            goal["n"] = N[i].round(6).tolist()
        alt = {**doc, "goals": [goal]}
        f = Path(os.environ.get("TMPDIR", "/tmp")) / f"{args.problem.stem}_goal{found}.toml"
        f.write_text(_toml(alt))
        row = {
            "goal": found,
            "state_index": int(i),
            "tip_over_R": round(float(np.linalg.norm(P[i])) / R, 3),
            "free_quarter": free_fractions(problem, checker, Q[i], range0)["0.25"],
        }
        for seed in (int(s) for s in args.seeds.split(",")):
            plan = pl.solve(
                pl.load_problem(f),
                "native.rrtconnect",
                seed,
                budget=pl.Budget(max_collision_checks=args.max_checks),
            )
            leg = plan.legs[0]
            nodes = (leg.extra or {}).get("nodes")
            row[f"seed{seed}"] = [leg.status.value, int(leg.collision_checks), nodes]
        print(json.dumps(row), flush=True)
    print(json.dumps({"load_end": os.getloadavg()}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
