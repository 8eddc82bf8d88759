"""The compiled core gives FCL's answers: verdicts and distances on many states per scene.

For each scene and each kind of state (uniform; coiled, every joint within ±0.3 rad of 0;
within ~1 mm of contact, see :mod:`plannerlab.collision.agreement`) it compares:

* verdicts of the core and of the FCL checker on every state;
* signed distances of every pair closer than 5 cm on the first ``--distance-states``
  states of each kind, core against FCL (``fcl.distance`` / ``fcl.collide`` depth);
* for ``--reference-pairs`` separated pairs per kind, the core against an independent
  bounded 1-D minimisation (scipy), which tells which of the two is right when they differ.

Verdicts that differ are listed with the core's clearance at that state: a state within
FCL's GJK tolerance of contact can be called either way.

    PYTHONPATH=. .venv/bin/python bench/core_agreement.py [--states 40000] [--scenes ...]

(40 000 states of each of the three kinds = 120 000 states per scene.)
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from plannerlab.collision.agreement import KINDS, compare, sample_states
from plannerlab.collision.core import Core
from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.problem.catalog import load_problem

SCENES = ("armz_inspection", "armz_pocket", "irb6_track_obstacle", "continuum_case3")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--states", type=int, default=40000, help="states of each kind")
    ap.add_argument("--distance-states", type=int, default=3000)
    ap.add_argument("--reference-pairs", type=int, default=300)
    ap.add_argument("--scenes", nargs="*", default=list(SCENES))
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    worst_ref = 0.0
    total_mismatch = 0
    for name in args.scenes:
        p = load_problem(name)
        core = Core(p.robot, p.scene)
        fcl = CollisionChecker(p.robot, p.scene, backend="fcl")
        for kind in KINDS:
            rng = np.random.default_rng(args.seed)
            t0 = time.perf_counter()
            Q = sample_states(core, kind, args.states, rng)
            a = compare(
                core,
                fcl,
                Q,
                distance_states=args.distance_states,
                reference_pairs=args.reference_pairs,
                rng=rng,
            )
            bad = np.flatnonzero(core.valid(Q) != fcl.valid_batch(Q))
            near = [core.clearance(Q[s]) for s in bad]
            worst_ref = max(worst_ref, a.max_err_ref_m)
            total_mismatch += len(bad)
            print(
                f"{name:20s} {kind:8s} {a.states:7d} states, {a.verdict_mismatches} verdicts "
                f"differ; {a.pairs_compared:6d} separated pairs: max |core-FCL| "
                f"{a.max_err_fcl_m:.2e} m, max |core-reference| {a.max_err_ref_m:.2e} m; "
                f"{a.pen_pairs} penetrating pairs: |core-FCL| median {a.median_pen_err_m:.2e} "
                f"m, max {a.max_pen_err_m:.2e} m  ({time.perf_counter() - t0:.0f} s)"
            )
            if len(bad):
                print(f"    core clearance at the differing states [m]: {np.round(near, 9)}")
    print(
        f"all scenes: {total_mismatch} differing verdicts; core vs independent minimisation "
        f"worst {worst_ref:.2e} m"
    )


if __name__ == "__main__":
    main()
