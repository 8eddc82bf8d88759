"""The simulator's clearance measure (``SimWorld.link_distances``) on the bundled mesh
Panda with and without the finer self-collision covers, in one run (issue 35): 50 seeded
states, ms a state.

    PYTHONPATH=. python bench/sim_distances_cost.py
"""

from __future__ import annotations

import dataclasses
import os
import time
from pathlib import Path

import numpy as np

from plannerlab.problem.catalog import load_problem
from plannerlab.sim import SimWorld

TABLE = Path(__file__).resolve().parents[1] / "problems" / "urdf" / "panda_mesh" / "table.toml"


def main() -> None:
    problem = load_problem(TABLE)
    print(f"load average {os.getloadavg()[0]:.1f}")
    for fine in (0, 128):
        robot = dataclasses.replace(problem.robot, self_cover_max_primitives=fine)
        Q = np.random.default_rng(0).uniform(robot.lower, robot.upper, size=(50, robot.dof))
        with SimWorld(robot, problem.scene) as probe:
            t, n = time.perf_counter(), 0
            for q in Q:
                if probe.set_state(q) is None:
                    probe.link_distances(0.05)
                    n += 1
            dt = (time.perf_counter() - t) / max(n, 1)
        print(f"self covers {fine}: {len(robot.link_names)} capsules, "
              f"{dt * 1e3:.1f} ms a state ({n} states)", flush=True)  # fmt: skip
    print(f"load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
