"""The metric edge bound of mesh arms (``collision/reach.py``: per joint, how fast any point
of the collision geometry can move [m per rad]) against the fastest capsule point (end
point speed plus radius) seen on 200 seeded random states, a lower bound of the true one.
The bound sets the edge grid with a margin (no point moves more than the margin between
checked states) and the certified stretches' growth. Printed: the bound used (the smaller
of the capsules' chain sum and the bodies', ``reach_bounds``) and the capsules' chain sum
alone (``capsule_reach_bounds``: the bound before the bodies' was taken, issue 35).

    PYTHONPATH=. python bench/mesh_reach_bound.py <erd> ur10,iiwa,z1 [--fine 0,128]

``<erd>`` as in ``bench/mesh_arms_bench.py``; a finer cover not yet cached is computed
(minutes for a large arm).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def main() -> int:
    import pybullet_data
    from mesh_arms_bench import ARMS

    from plannerlab.collision.reach import capsule_reach_bounds, reach_bounds
    from plannerlab.robots.urdf.model import UrdfChain
    from plannerlab.run.robot_info import default_tip_link

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("erd", type=Path, help="example-robot-data's robots/")
    ap.add_argument("arms", help="comma-separated, of " + ",".join(ARMS))
    ap.add_argument("--fine", default="0,128", help="self_cover_max_primitives to try")
    args = ap.parse_args()
    h = 1e-6
    for arm in args.arms.split(","):
        source, rel = ARMS[arm]
        urdf = (args.erd if source == "erd" else Path(pybullet_data.getDataPath())) / rel
        for fine in (int(f) for f in args.fine.split(",")):
            robot = UrdfChain(urdf, default_tip_link(urdf), self_cover_max_primitives=fine)
            bound = reach_bounds(robot)[0]
            capsules = capsule_reach_bounds(robot)[0]
            Q = np.random.default_rng(1).uniform(robot.lower, robot.upper, (200, robot.dof))
            S = np.asarray(robot.link_segments(Q))
            radii = np.asarray(robot.link_radii_m)
            seen = np.zeros(robot.dof)
            for i in range(robot.dof):
                Qh = Q.copy()
                Qh[:, i] += h
                speed = np.linalg.norm((np.asarray(robot.link_segments(Qh)) - S) / h, axis=-1)
                ends = speed.max(axis=-1)  # (states, capsules)
                seen[i] = float((ends + radii[None] * (ends > 1e-9)).max())
            ratio = bound / np.maximum(seen, 1e-9)
            before = capsules / np.maximum(seen, 1e-9)
            print(
                f"{arm} self_cover_max_primitives={fine} capsules={len(radii)}: "
                f"bound {np.round(bound, 2).tolist()} seen {np.round(seen, 2).tolist()} "
                f"ratio {np.round(ratio, 1).tolist()} (the capsules' chain sum alone: "
                f"bound {np.round(capsules, 2).tolist()} ratio {np.round(before, 1).tolist()})",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
