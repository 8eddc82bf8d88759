"""The clearance descent towards goal states against the same descent towards tip goals,
on the room variants: how often does it reach a goal state?

For each variant (``problems/variants/armz_inspection_<v>.toml``) every leg is planned
twice from the previous leg's witness state (the start for leg 0): towards the leg's tip
goal (position and normal) and towards the leg's witness state as a goal state
(:class:`~plannerlab.problem.goals.JointGoal`, ``--tol`` rad). Prints per variant one mark
per leg (``j+``/``j-``: the goal state reached or not; ``t+``/``t-``: the tip goal) and
the totals. Budgets are collision checks and iterations, so the counts do not depend on
the machine.

    PYTHONPATH=. .venv/bin/python bench/joint_goal_bench.py
        [--planner gradient.clearance+detour] [--variants v00,...,v07] [--tol 0.01]
        [--max-checks 20000] [--seed 0]
"""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np

from plannerlab.planners import make_planner
from plannerlab.problem.goals import JointGoal
from plannerlab.problem.load import Budget, parse_problem


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--planner", default="gradient.clearance+detour")
    ap.add_argument("--variants", default=",".join(f"v{i:02d}" for i in range(8)))
    ap.add_argument("--tol", type=float, default=0.01, help="goal states' joint tolerance [rad]")
    ap.add_argument("--max-checks", type=int, default=20000)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    budget = Budget(max_collision_checks=args.max_checks, max_iterations=args.max_checks)
    solved = {"joint": 0, "tip": 0}
    legs = 0
    for v in args.variants.split(","):
        problem = parse_problem(f"problems/variants/armz_inspection_{v}.toml")
        W = np.array(problem.extras["witness"]["goal_states_rad"], dtype=float)
        goals = tuple(
            JointGoal.at(problem.robot, g.name, w, args.tol)
            for g, w in zip(problem.goals, W, strict=True)
        )
        to_states = dataclasses.replace(problem, goals=goals)
        marks = []
        for leg in range(len(W)):
            q0 = problem.q_start if leg == 0 else W[leg - 1]
            legs += 1
            for kind, p in (("joint", to_states), ("tip", problem)):
                r = make_planner(args.planner).solve(
                    p, leg, budget, np.random.default_rng(args.seed), q_start=q0
                )
                solved[kind] += int(r.solved)
                marks.append(f"{kind[0]}{'+' if r.solved else '-'}")
        print(v, " ".join(marks), flush=True)
    print(
        f"{args.planner}: {legs} legs; solved towards goal states {solved['joint']}, "
        f"towards tip goals {solved['tip']}"
    )


if __name__ == "__main__":
    main()
