"""The state test's cost on a mesh robot with and without its finer self-collision covers,
in one run (issue 35): seeded random states, no scene, ``valid_batch`` best of 5.

    PYTHONPATH=. python bench/mesh_self_cost.py URDF [--states 300]
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from mesh_self_validity import batch_verdicts  # noqa: E402

from plannerlab.collision.fcl_checker import CollisionChecker  # noqa: E402
from plannerlab.problem.scene import Scene  # noqa: E402
from plannerlab.robots.urdf.model import UrdfChain  # noqa: E402
from plannerlab.run.robot_info import default_tip_link  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("urdf", type=Path)
    ap.add_argument("--states", type=int, default=300)
    args = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.1f}")
    cost = {}
    for fine in (0, 128):
        r = UrdfChain(args.urdf, default_tip_link(args.urdf), self_cover_max_primitives=fine)
        ck = CollisionChecker(r, Scene(), backend="core")  # type: ignore[arg-type]
        Q = np.random.default_rng(0).uniform(r.lower, r.upper, size=(args.states, r.dof))
        ok, best = batch_verdicts(ck, Q, 5)
        cost[fine] = best / len(Q) * 1e6
        print(f"self covers {fine}: {len(r.link_names)} capsules, {np.mean(ok):.1%} valid, "
              f"{cost[fine]:.2f} us/state", flush=True)  # fmt: skip
    print(f"ratio {cost[128] / cost[0]:.1f}x, load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
