"""The path clearance measure on a mesh arm (``Core.min_clearance``, which
``run/pipeline.path_clearance_m`` calls on every state of the final re-check's grid),
before and after issue 35's two changes, in one run:

* the measure per state: the kernel before the body gates (a box gap for every capsule
  pair, kept here verbatim) against ``kernels.min_clearance_kernel`` (a body pair, or a
  body and an obstacle, whose boxes are further apart than the best so far opens no
  capsule pair), on the same states, the same value asserted;
* the grid it runs over: the states of a path's re-check grid at ``joint_step / 4`` with
  the capsules' reach bound (``reach.capsule_reach_bounds``, before) and the bound used
  (``reach.reach_bounds``, the bodies' too), and the whole measure's time on each.

    PYTHONPATH=. python bench/mesh_clearance_cost.py <erd> ur10 [--fine 128] [--states 400]

``<erd>`` as in ``bench/mesh_arms_bench.py``. Prints the machine's load.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path

import numpy as np
from numba import njit

from plannerlab.collision.geometry import capsule_obstacle, seg_seg
from plannerlab.collision.kernels import box_gap, link_boxes
from plannerlab.collision.simd import unliteral

sys.path.insert(0, str(Path(__file__).resolve().parent))


@njit(cache=True)
def previous_min_clearance(segs, geo, include_self):
    """``min_clearance_kernel`` before the body gates (every capsule pair's box gap; it
    knows no declared contacts, ``geo.touch``: compared on scenes without them)."""
    radii, radii_self, moving, allowed, tree, kinds, Rs, cs, hs, olo, ohi = geo[:11]
    L = segs.shape[1]
    n_obs = kinds.shape[0]
    lo = np.empty((L, 3))
    hi = np.empty((L, 3))
    lo2 = np.empty((L, 3))
    hi2 = np.empty((L, 3))
    nv = np.empty(3)
    w = np.zeros(32)
    best = np.inf
    for s in range(segs.shape[0]):
        seg = segs[s]
        link_boxes(seg, radii, lo, hi)
        for li in range(L):
            if not moving[li]:
                continue
            for oi in range(n_obs):
                g = box_gap(lo, hi, li, olo, ohi, oi)
                if g > 0.0 and g >= best:
                    continue
                dist, _ = capsule_obstacle(
                    (kinds, Rs, cs, hs),
                    oi,
                    seg[li, 0],
                    seg[li, 1],
                    radii[li],
                    unliteral(False),
                    nv,
                    w,
                )
                if dist < best:
                    best = dist
        if not include_self:
            continue
        link_boxes(seg, radii_self, lo2, hi2)
        for i in range(L):
            for j in range(i + 1, L):
                if not allowed[i, j]:
                    continue
                g = box_gap(lo2, hi2, i, lo2, hi2, j)
                if g > 0.0 and g >= best:
                    continue
                d2, _, _ = seg_seg(seg[i, 0], seg[i, 1], seg[j, 0], seg[j, 1])
                dist = math.sqrt(d2) - radii_self[i] - radii_self[j]
                if dist < best:
                    best = dist
    return best


def _timed(f, *args):
    t = time.process_time()
    out = f(*args)
    return out, time.process_time() - t


def main() -> int:
    import pybullet_data
    from mesh_arms_bench import ARMS

    from plannerlab.collision.core import Core
    from plannerlab.collision.kernels import min_clearance_kernel
    from plannerlab.collision.reach import capsule_reach_bounds, reach_bounds
    from plannerlab.problem.scene import Box, Scene
    from plannerlab.robots.base import pose_matrix
    from plannerlab.robots.urdf.model import UrdfChain
    from plannerlab.run.robot_info import default_tip_link

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("erd", type=Path, help="example-robot-data's robots/")
    ap.add_argument("arm", help="one of " + ",".join(ARMS))
    ap.add_argument("--fine", type=int, default=128, help="self_cover_max_primitives")
    ap.add_argument("--states", type=int, default=400, help="states a measure")
    ap.add_argument("--margin", type=float, default=0.01, help="clearance margin [m]")
    args = ap.parse_args()
    print(f"load average at start: {os.getloadavg()}", flush=True)
    source, rel = ARMS[args.arm]
    urdf = (args.erd if source == "erd" else Path(pybullet_data.getDataPath())) / rel
    robot = UrdfChain(urdf, default_tip_link(urdf), self_cover_max_primitives=args.fine)
    reach = robot.link_segments(np.zeros(robot.dof)).reshape(-1, 3)
    top = float(reach[:, 2].max())
    # a table under the arm and a wall beside it: the scene part of the measure
    scene = Scene(
        (
            Box("table", pose_matrix([0.6, 0.0, -0.05], [0, 0, 0]), [0.8, 1.2, 0.04]),
            Box("wall", pose_matrix([0.0, 0.9, top / 2], [0, 0, 0]), [1.6, 0.04, top + 0.4]),
        )
    )
    core = Core(robot, scene, margin_m=args.margin)
    rng = np.random.default_rng(0)
    # a path of valid waypoints, each within 0.5 rad a joint of the one before
    waypoints = [rng.uniform(robot.lower, robot.upper)]
    while not core.is_valid(waypoints[0]):
        waypoints[0] = rng.uniform(robot.lower, robot.upper)
    while len(waypoints) < 4:
        q = np.clip(waypoints[-1] + rng.uniform(-0.5, 0.5, robot.dof), robot.lower, robot.upper)
        if core.is_valid(q):
            waypoints.append(q)
    waypoints = np.array(waypoints)
    # a path's grid: nearby states, as the re-check measures them
    t = np.linspace(0.0, 1.0, args.states)[:, None]
    Q = waypoints[0] + t * (waypoints[1] - waypoints[0])
    segs = core.segments(Q)
    previous_min_clearance(segs[:2], core._geo, True)  # compiled before timing
    min_clearance_kernel(segs[:2], core._geo, True)
    print(f"{args.arm}, finer covers {args.fine}: {core.n_links} capsules, {len(Q)} states")
    for include_self in (True, False):
        a, ta = _timed(previous_min_clearance, segs, core._geo, include_self)
        b, tb = _timed(min_clearance_kernel, segs, core._geo, include_self)
        assert abs(a - b) <= 1e-12, (a, b)
        print(
            f"  include_self={include_self}: previous {1e6 * ta / len(Q):.1f} us a state, "
            f"gated {1e6 * tb / len(Q):.1f} us a state ({ta / max(tb, 1e-12):.1f}x); "
            f"clearance {1e3 * b:.2f} mm both"
        )
    step = 0.02 / 4.0  # the re-check's grid at a joint_step of 0.02 rad
    for name, bound in (
        ("capsules' bound (before)", capsule_reach_bounds(robot)[0]),
        ("bound used (after)", reach_bounds(robot)[0]),
    ):
        d = np.abs(np.diff(waypoints, axis=0))  # no continuous joints on these arms
        n = np.maximum(np.ceil(d.max(axis=1) / step), np.ceil(d @ (bound / args.margin)))
        print(f"  re-check grid of a 3-edge path, {name}: {int(n.sum())} states", flush=True)
    print(f"load average at end: {os.getloadavg()}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
