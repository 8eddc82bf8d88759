"""What a state and an edge cost on a mesh robot's covers (issue 35, item 6): the OMPL
adapter's edges are the checker's ``check_edge``; with a safety margin they run by
conservative advancement (one distance step per state), else on the metric grid.

    python bench/mesh_edge_cost.py problems/urdf/panda_mesh/table.toml [--edges 60]

Prints the load average, per state the time of one validity check, and per edge (0.3
rad from seeded valid states) the time, the states and the time per state of both modes,
and their ratio (measured in this run)."""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from plannerlab.collision.fcl_checker import problem_checker
from plannerlab.problem.catalog import load_problem


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("problem")
    ap.add_argument("--edges", type=int, default=60)
    args = ap.parse_args()
    print(f"load average: {os.getloadavg()}")
    p = load_problem(args.problem)
    ck = problem_checker(p)
    r = p.robot
    rng = np.random.default_rng(0)
    Q = rng.uniform(r.lower, r.upper, size=(400, r.dof))
    ck.is_valid(Q[0])
    ck.check_edge(Q[0], Q[1], 0.02)  # compiled paths warm
    t = time.perf_counter()
    valid = np.array([ck.is_valid(q) for q in Q])
    per_state = (time.perf_counter() - t) / len(Q)
    print(f"{len(r.link_names)} capsules; a state: {per_state * 1e6:.1f} us")
    V = Q[valid]
    edges = []
    for i in range(min(args.edges, len(V) - 1)):
        d = V[i + 1] - V[i]
        edges.append((V[i], V[i] + 0.3 * d / max(float(np.max(np.abs(d))), 1e-9)))
    cost = {}
    for mode in ("advance", "grid"):
        ck.edge_check = mode
        t = time.perf_counter()
        n = sum(ck.check_edge(a, b, p.joint_step)[0] for a, b in edges)
        dt = time.perf_counter() - t
        cost[mode] = dt / len(edges)
        print(
            f"{mode}: {dt / len(edges) * 1e3:.2f} ms an edge, {n / len(edges):.1f} states, "
            f"{dt / max(n, 1) * 1e6:.1f} us a state"
        )
    print(f"advance / grid per edge: {cost['advance'] / cost['grid']:.2f}")


if __name__ == "__main__":
    main()
