"""What mesh covers cost the compiled core: validity checks per second of PyBullet's mesh
Panda (sphere covers, ``problems/urdf/panda_mesh``) against MotionBenchMaker's spherized
Panda, in the same scene (the table problem's boxes and ring cover) and the same run.

    python bench/mesh_core_bench.py [--states 4000] [--rounds 3]

Prints the capsule count of each model, the time per state of ``valid_batch`` over the
same seeded states (best of the rounds), their ratio, the share of states each finds
valid, and the machine's load.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

import numpy as np

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.problem.catalog import load_problem
from plannerlab.robots.urdf.model import UrdfChain

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--states", type=int, default=4000)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    problem = load_problem(ROOT / "problems/urdf/panda_mesh/table.toml")
    mesh = problem.robot
    sph_dir = ROOT / "problems/urdf/panda"
    spherized = UrdfChain(
        sph_dir / "panda_spherized.urdf",
        "panda_hand",
        srdf_path=sph_dir / "panda.srdf",
    )
    rng = np.random.default_rng(0)
    lo, hi = np.asarray(mesh.lower), np.asarray(mesh.upper)
    Q = lo + rng.random((args.states, mesh.dof)) * (hi - lo)
    rows = []
    for name, robot in (("spherized", spherized), ("mesh covers", mesh)):
        checker = CollisionChecker(robot, problem.scene, backend="core")
        checker.valid_batch(Q[:10])  # compile / load
        best = np.inf
        for _ in range(args.rounds):
            t = time.perf_counter()
            valid = checker.valid_batch(Q)
            best = min(best, time.perf_counter() - t)
        rows.append((name, len(robot.link_names), best / len(Q), float(np.mean(valid))))
    base = rows[0][2]
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    for name, n, per, share in rows:
        print(
            f"{name:12s} {n:4d} capsules  {per * 1e6:8.1f} us/state  "
            f"x{per / base:5.1f}  valid {share:.2f}"
        )


if __name__ == "__main__":
    main()
