"""Per-trial start-up of ``plannerlab compare``: fork server against spawned interpreters.

Usage:

    PYTHONPATH=. python bench/trial_startup_bench.py [N]   # N trials per start method (6)

Runs the same N small trials (``armz_pocket``, ``ompl.rrtconnect``, 300 collision checks,
seeds 0..N-1, one at a time) through :func:`plannerlab.comparison.runner.run_comparison` with
the local backend's two start methods, in this one process. Start-up is what each child
records as ``startup_s``: from the parent's launch of the trial to the child being ready
to load the problem, plannerlab's trial modules (numpy, FCL, PyBullet, OMPL, toppra, the
planners) imported. Prints the median and the range per method, the ratio, and whether
both methods gave the same paths.
"""

from __future__ import annotations

import statistics
import sys
import tempfile
from pathlib import Path


def main(argv: list[str]) -> int:
    from plannerlab.comparison.local import LocalBackend
    from plannerlab.comparison.runner import run_comparison
    from plannerlab.comparison.trial import Trial, run_trial
    from plannerlab.problem.catalog import resolve_problem_path
    from plannerlab.record.files import versions

    n = int(argv[0]) if argv else 6
    path = resolve_problem_path("armz_pocket").resolve()
    trials = [
        Trial.make("armz_pocket", path, "ompl.rrtconnect", s, budget={"max_collision_checks": 300})
        for s in range(n)
    ]
    print(f"{n} trials per method: armz_pocket, ompl.rrtconnect, 300 checks; {versions()}")
    med = {}
    paths = {}
    with tempfile.TemporaryDirectory() as tmp:
        for method in ("spawn", "forkserver"):
            backend = LocalBackend(Path(tmp) / f"run-{method}", run_trial, start_method=method)
            try:
                run = run_comparison(trials, Path(tmp) / f"{method}.jsonl", backend=backend)
            finally:
                backend.close()
            ups = [r.startup_s or 0.0 for r in run.records]
            med[method] = statistics.median(ups)
            paths[method] = [leg.path_sha256 for r in run.records for leg in r.legs_run]
            print(
                f"{method:>10}: start-up median {med[method]:.3f} s "
                f"(min {min(ups):.3f}, max {max(ups):.3f})"
            )
    print(f"start-up ratio spawn / forkserver: {med['spawn'] / med['forkserver']:.1f}x")
    print(f"same paths with both methods: {paths['spawn'] == paths['forkserver']}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
