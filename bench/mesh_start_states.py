"""Why an arm of ``bench/mesh_arms_bench.py`` gets no problem: of the seeded random states
whose tip lies in a problem's start region (the bench's own states and regions), how many
are valid, with the first covers alone and with the finer self-collision covers, at the
bench's margin (1.2 % of the reach) and at none, and which pairs collide most.

    PYTHONPATH=. python bench/mesh_start_states.py <erd> ur10 [--states 300] [--fine 0,128]

``<erd>`` as in ``bench/mesh_arms_bench.py``.
"""

from __future__ import annotations

import argparse
import collections
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def main() -> int:
    import pybullet_data
    from mesh_arms_bench import ARMS, scenes

    from plannerlab.collision.fcl_checker import problem_checker
    from plannerlab.problem.load import problem_from_dict
    from plannerlab.robots.urdf.model import UrdfChain
    from plannerlab.run.robot_info import default_tip_link

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("erd", type=Path, help="example-robot-data's robots/")
    ap.add_argument("arm", choices=sorted(ARMS))
    ap.add_argument("--states", type=int, default=300, help="region states at most")
    ap.add_argument("--fine", default="0,128", help="self_cover_max_primitives to try")
    args = ap.parse_args()
    source, rel = ARMS[args.arm]
    urdf = (args.erd if source == "erd" else Path(pybullet_data.getDataPath())) / rel
    tip = default_tip_link(urdf)
    robot = UrdfChain(urdf, tip)
    Q = np.random.default_rng(0).uniform(robot.lower, robot.upper, size=(20000, robot.dof))
    P, _ = robot.tip(Q)
    R = float(np.max(np.linalg.norm(P, axis=1)))
    for name, (obstacles, start_box, _) in scenes(R).items():
        lo, hi = np.asarray(start_box[0]), np.asarray(start_box[1])
        idx = np.flatnonzero(np.all((P >= lo) & (P <= hi), axis=1))[: args.states]
        for fine in (int(f) for f in args.fine.split(",")):
            for margin in (round(0.012 * R, 4), 0.0):
                doc = {
                    "problem": {"name": "probe"},
                    "robot": {
                        "type": "urdf",
                        "urdf": str(urdf.resolve()),
                        "tip_link": tip,
                        "self_cover_max_primitives": fine,
                    },
                    "planning": {"safety_margin_m": margin},
                    "obstacles": obstacles,
                    "start": {"q": Q[0].tolist()},
                    "goals": [{"name": "g", "q": Q[1].tolist()}],
                }
                t0 = time.perf_counter()
                checker = problem_checker(problem_from_dict(doc, "probe.toml"))
                ok = np.array([checker.is_valid(Q[i]) for i in idx], dtype=bool)
                pairs: collections.Counter[tuple[str, ...]] = collections.Counter()
                for i in idx[~ok][:100]:
                    for pair in checker.colliding_pairs(Q[i]):
                        pairs[tuple(s.split("#")[0] for s in pair)] += 1
                print(
                    f"{args.arm} {name} self_cover_max_primitives={fine} margin={margin} m: "
                    f"{int(ok.sum())}/{len(idx)} valid ({time.perf_counter() - t0:.0f} s); "
                    f"most colliding (capsule pairs in <= 100 invalid states): "
                    f"{pairs.most_common(4)}",
                    flush=True,
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
