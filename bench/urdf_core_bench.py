"""A URDF robot (MotionBenchMaker's spherized Panda) on the compiled core: verdicts against
FCL on random states in imported MotionBenchMaker scenes, and the cost per state.

Import the problems first (``plannerlab import mbm --fetch --limit 1 --out DIR``), then

    PYTHONPATH=. .venv/bin/python bench/urdf_core_bench.py DIR [--states 7200]

For every ``*_0001.toml`` in DIR and for margins 0 and 0.01 m it checks ``--states``
uniform random states with the core and with FCL and counts the verdicts that differ;
then, on the first problem, it times the core's kinematics, batched validity and one
state at a time (the least of 7 repetitions, so that other load on the machine counts
least).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.problem.load import parse_problem


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("folder", type=Path)
    ap.add_argument("--states", type=int, default=7200)
    args = ap.parse_args()
    files = sorted(args.folder.glob("*_0001.toml"))
    total = differ = 0
    for f in files:
        p = parse_problem(f)
        for margin in (0.0, 0.01):
            core = CollisionChecker(p.robot, p.scene, backend="core", margin_m=margin)
            fcl = CollisionChecker(p.robot, p.scene, backend="fcl", margin_m=margin)
            Q = np.random.default_rng(11).uniform(p.robot.lower, p.robot.upper, (args.states, 7))
            a, b = core.valid_batch(Q), fcl.valid_batch(Q)
            total += len(Q)
            differ += int(np.sum(a != b))
            print(
                f"{f.stem:24s} margin {margin:4.2f} m  valid {a.mean():.3f}  "
                f"differ {np.sum(a != b)}"
            )
    print(f"{total} states, {differ} verdicts differ")
    p = parse_problem(files[0])
    checker = CollisionChecker(p.robot, p.scene, backend="core")
    assert checker._core is not None
    Q = np.random.default_rng(0).uniform(p.robot.lower, p.robot.upper, (2000, 7))
    kin, batch, one = [], [], []
    for _ in range(7):
        t = time.perf_counter()
        checker._core.segments(Q)
        kin.append((time.perf_counter() - t) / len(Q))
        t = time.perf_counter()
        checker.valid_batch(Q)
        batch.append((time.perf_counter() - t) / len(Q))
        t = time.perf_counter()
        for q in Q[:500]:
            checker.is_valid(q)
        one.append((time.perf_counter() - t) / 500)
    print(
        f"{files[0].stem}: kinematics {min(kin) * 1e6:.2f} µs/state, batched validity "
        f"{min(batch) * 1e6:.2f} µs/state, one state at a time {min(one) * 1e6:.2f} µs/state"
    )


if __name__ == "__main__":
    main()
