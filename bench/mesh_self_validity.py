"""How much of a mesh robot's joint space its covers call free, against its real meshes
(issue 35): seeded random states, no scene; plannerlab's checker on the covers (each
``--budgets`` value of ``cover_max_primitives``) and PyBullet on the URDF's meshes
(``URDF_USE_SELF_COLLISION``, contacts between links that are not parent and child).

    python bench/mesh_self_validity.py URDF [--tip LINK] [--states 300] [--budgets 32,64]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
import pybullet as pb

sys.path.insert(0, str(Path(__file__).resolve().parent))
from mesh_referee import _shipped_urdf  # noqa: E402

from plannerlab.collision.fcl_checker import CollisionChecker  # noqa: E402
from plannerlab.problem.scene import Scene  # noqa: E402
from plannerlab.robots.urdf.model import UrdfChain  # noqa: E402
from plannerlab.run.robot_info import default_tip_link  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("urdf", type=Path)
    ap.add_argument("--tip")
    ap.add_argument("--states", type=int, default=300)
    ap.add_argument("--budgets", default="32")
    args = ap.parse_args()
    tip = args.tip or default_tip_link(args.urdf)
    for b in (int(x) for x in args.budgets.split(",")):
        r = UrdfChain(args.urdf, tip, cover_max_primitives=b)
        Q = np.random.default_rng(0).uniform(r.lower, r.upper, size=(args.states, r.dof))
        ck = CollisionChecker(r, Scene(), backend="core")  # type: ignore[arg-type]
        worst = max(c.max_excess_m for c in r.mesh_covers) * 1e3
        ok = np.mean([ck.is_valid(q) for q in Q])
        print(
            f"covers, {b} a mesh: {len(r.link_names)} primitives, worst {worst:.1f} mm: "
            f"{ok:.1%} valid"
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
    print(f"real meshes (PyBullet): {free / len(Q):.1%} valid")


if __name__ == "__main__":
    main()
