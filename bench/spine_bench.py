"""Baseline speeds of the spine, measured in one run on the same random states.

Prints each operation's time per call and its ratio to the first row (single-state
forward kinematics), so later speed work can compare ratios measured on one machine in
one run. Nothing here is asserted: tests never time anything.

    .venv/bin/python bench/spine_bench.py [--states 2000]
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import numpy as np
from rich.console import Console
from rich.table import Table

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.planners import make_planner
from plannerlab.planners.objective import Objective
from plannerlab.problem.catalog import load_problem


def per_call(fn: Callable[[], object], calls: int) -> float:
    """Best of three runs of ``calls`` calls, seconds per call."""
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        for _ in range(calls):
            fn()
        best = min(best, (time.perf_counter() - t0) / calls)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--states", type=int, default=2000)
    ap.add_argument("--problem", default="armz_inspection")
    args = ap.parse_args()
    problem = load_problem(args.problem)
    robot = problem.robot
    rng = np.random.default_rng(0)
    Q = rng.uniform(robot.lower, robot.upper, (args.states, robot.dof))
    checker = CollisionChecker(robot, problem.scene)
    f = Objective(robot, problem.goal(0), checker)
    fd = make_planner("gradient")
    an = make_planner("gradient.analytic")
    it = iter(range(10**9))

    def q() -> np.ndarray:
        return Q[next(it) % len(Q)]

    rows: list[tuple[str, float, str]] = []
    rows.append(("fk, one state", per_call(lambda: robot.fk(q()), 2000), "per state"))
    rows.append(("fk, batch of all states", per_call(lambda: robot.fk(Q), 3) / len(Q), "per state"))
    rows.append(
        ("validity check, one state", per_call(lambda: checker.is_valid(q()), 1000), "per state")
    )
    rows.append(
        ("validity check, batch", per_call(lambda: checker.valid_batch(Q), 1) / len(Q), "per state")
    )
    rows.append(
        (
            "gradient, finite differences (approx_fprime)",
            per_call(lambda: fd.gradient(f, q()), 50),
            "per gradient",
        )
    )
    rows.append(("gradient, analytic", per_call(lambda: an.gradient(f, q()), 500), "per gradient"))
    try:
        from plannerlab.sim import SimWorld

        with SimWorld(robot, problem.scene) as world:
            world.reset(problem.q_start)
            target = problem.q_start + 0.01
            wall = per_call(lambda: world.move_towards(target, 100), 5)
        sim_s = 100 / 240
        rows.append(
            (
                "closed-loop iteration (100 PyBullet steps)",
                wall,
                f"{sim_s / wall:.1f}x faster than real time ({sim_s:.3f} s simulated)",
            )
        )
    except ImportError as exc:  # pragma: no cover - the sim package is part of the install
        rows.append((f"closed-loop iteration: {exc}", float("nan"), ""))

    base = rows[0][1]
    table = Table(
        title=f"spine baseline on {problem.name} ({robot.dof} joints, "
        f"{len(problem.scene.obstacles)} obstacles, {len(Q)} random states)"
    )
    for col in ("operation", "time", "x fk(one state)", "note"):
        table.add_column(col)
    for name, sec, note in rows:
        table.add_row(name, f"{sec * 1e6:,.1f} µs", f"{sec / base:,.1f}", note)
    Console().print(table)


if __name__ == "__main__":
    main()
