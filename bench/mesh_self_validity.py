"""How much of a mesh robot's joint space its covers call free, against its real meshes
(issue 35): seeded random states, no scene; plannerlab's checker on the covers (each
``--budgets`` value of ``cover_max_primitives``, each ``--self`` value of
``self_cover_max_primitives``: 0 = the first cover judges self-collision too) and
PyBullet on the URDF's meshes (``URDF_USE_SELF_COLLISION``, contacts between links that
are not parent and child). Per model: capsules, worst excess of each tier, the share
valid, the state test's cost (``valid_batch``, best of 3, same run), and the states it
calls valid that PyBullet finds colliding (must be 0: the covers are conservative).

    python bench/mesh_self_validity.py URDF [--tip LINK] [--states 300] [--budgets 32,64]
        [--self 0,128]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pybullet as pb

sys.path.insert(0, str(Path(__file__).resolve().parent))
from mesh_referee import _shipped_urdf  # noqa: E402

from plannerlab.collision.fcl_checker import CollisionChecker  # noqa: E402
from plannerlab.problem.scene import Scene  # noqa: E402
from plannerlab.robots.urdf.model import UrdfChain  # noqa: E402
from plannerlab.run.robot_info import default_tip_link  # noqa: E402


def batch_verdicts(ck: CollisionChecker, Q: np.ndarray, repeats: int) -> tuple[np.ndarray, float]:
    """The batch's verdicts and the best of ``repeats`` timings of ``valid_batch`` [s]
    (kernels loaded first)."""
    ck.valid_batch(Q[:8])  # compile / load
    best = np.inf
    for _ in range(repeats):
        t = time.perf_counter()
        ok = ck.valid_batch(Q)
        best = min(best, time.perf_counter() - t)
    return ok, best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("urdf", type=Path)
    ap.add_argument("--tip")
    ap.add_argument("--states", type=int, default=300)
    ap.add_argument("--budgets", default="32")
    ap.add_argument("--self", default="0,128")
    args = ap.parse_args()
    tip = args.tip or default_tip_link(args.urdf)
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    verdicts = {}
    for b in (int(x) for x in args.budgets.split(",")):
        for f in (int(x) for x in args.self.split(",")):
            t0 = time.perf_counter()
            r = UrdfChain(args.urdf, tip, cover_max_primitives=b, self_cover_max_primitives=f)
            load_s = time.perf_counter() - t0
            Q = np.random.default_rng(0).uniform(r.lower, r.upper, size=(args.states, r.dof))
            ck = CollisionChecker(r, Scene(), backend="core")  # type: ignore[arg-type]
            ok, best = batch_verdicts(ck, Q, 3)
            verdicts[(b, f)] = ok
            worst = max(c.max_excess_m for c in r.mesh_covers) * 1e3
            fine = max((c.max_excess_m for c in r.self_covers), default=float("nan")) * 1e3
            print(
                f"covers {b}/mesh, self covers {f}/mesh: {len(r.link_names)} capsules "
                f"({len(r.self_only_links)} self only), worst excess {worst:.1f} mm "
                f"(self covers {fine:.1f} mm), load {load_s:.1f} s: {np.mean(ok):.1%} valid, "
                f"{best / len(Q) * 1e6:.1f} us/state",
                flush=True,
            )
    c = pb.connect(pb.DIRECT)
    with tempfile.TemporaryDirectory() as tmp:
        body = pb.loadURDF(
            str(_shipped_urdf(args.urdf, Path(tmp))),
            useFixedBase=True,
            flags=pb.URDF_USE_SELF_COLLISION,
            physicsClientId=c,
        )
    n = pb.getNumJoints(body, physicsClientId=c)
    idx = {pb.getJointInfo(body, j, physicsClientId=c)[1].decode(): j for j in range(n)}
    joints = [idx[name] for name in r.joint_names]
    parent = {j: pb.getJointInfo(body, j, physicsClientId=c)[16] for j in range(n)}
    free = 0
    real = []
    for q in Q:
        for j, v in zip(joints, q, strict=True):
            pb.resetJointState(body, j, float(v), physicsClientId=c)
        pb.performCollisionDetection(physicsClientId=c)
        hit = any(
            pt[8] <= 0
            and pt[3] != pt[4]
            and parent.get(pt[3]) != pt[4]
            and parent.get(pt[4]) != pt[3]
            for pt in pb.getContactPoints(body, body, physicsClientId=c)
        )
        free += not hit
        real.append(not hit)
    print(f"real meshes (PyBullet): {free / len(Q):.1%} valid")
    for (b, f), ok in verdicts.items():
        wrong = int(np.sum(ok & ~np.array(real)))
        print(f"covers {b}/{f}: {wrong} states valid on the covers, colliding on the meshes")


if __name__ == "__main__":
    main()
