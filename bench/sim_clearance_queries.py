"""The simulator's clearance query (``SimWorld.link_distances``), its parts asked two ways
each, in one run, on the same seeded states: ms a state, and whether the distances agree.

* self, ``whole``: the body against itself in one PyBullet call (link_distances before
  `HEAD`: PyBullet then also measures the pairs the checker never checks, adjacent links
  overlapping at their joints); ``pairs``: each checked link pair in its own call
  (today's);
* scene, ``whole``: the body against each obstacle in one call (today's); ``links``: each
  moving link against each obstacle in its own call (fixed links skipped);
* ``link_distances``: today's whole query, as the executor calls it.

Problems: the bundled Arm-Z task, mesh Panda and mesh iiwa, and any TOML given.

    PYTHONPATH=. python bench/sim_clearance_queries.py [PROBLEM.toml ...] [--reach 0.05]
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.problem.catalog import load_problem
from plannerlab.sim import SimWorld
from plannerlab.sim.measure import _link_groups

PROBLEMS = Path(__file__).resolve().parents[1] / "problems"
BUNDLED = [
    "armz_inspection",
    str(PROBLEMS / "urdf" / "panda_mesh" / "table.toml"),
    str(PROBLEMS / "urdf" / "iiwa_mesh" / "table.toml"),
]


def _self(w: SimWorld, dmax: float, group: np.ndarray, G: int, whole: bool) -> np.ndarray:
    c = w.client
    pair = np.full((G, G), dmax)
    if whole:
        points = c.getClosestPoints(w.body, w.body, dmax)
    else:
        points = [
            pt
            for a, b, _, _ in w._self_queries
            for pt in c.getClosestPoints(w.body, w.body, dmax, a, b)
        ]
    for pt in points:
        i, k = w._robot_link.get(pt[3]), w._robot_link.get(pt[4])
        if i is None or k is None or w._unchecked_pairs[i, k]:
            continue
        g, h = group[i], group[k]
        pair[g, h] = pair[h, g] = min(pair[g, h], pt[8])
    return pair


def _scene(w: SimWorld, dmax: float, group: np.ndarray, G: int, whole: bool) -> np.ndarray:
    c, fixed = w.client, set(w.robot.fixed_links)
    scene = np.full(G, dmax)
    moving = [a for a, i in w._robot_link.items() if i not in fixed]
    for uid in w.obstacle_names:
        if whole:
            points = c.getClosestPoints(w.body, uid, dmax)
        else:
            points = [pt for a in moving for pt in c.getClosestPoints(w.body, uid, dmax, a)]
        for pt in points:
            i = w._robot_link.get(pt[3])
            if i is not None and i not in fixed:
                scene[group[i]] = min(scene[group[i]], pt[8])
    return scene


def _timed(acc: dict[str, float], key: str, f: Callable[..., Any], *args: Any) -> Any:
    t = time.perf_counter()
    out = f(*args)
    acc[key] = acc.get(key, 0.0) + time.perf_counter() - t
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("problems", nargs="*")
    ap.add_argument("--reach", type=float, default=0.05, help="max distance read [m]")
    ap.add_argument("--states", type=int, default=40)
    args = ap.parse_args()
    dmax = args.reach
    print(f"load average {os.getloadavg()[0]:.1f}; reach {dmax} m; ms a state")
    for name in args.problems or BUNDLED:
        problem = load_problem(name)
        robot = problem.robot
        groups = _link_groups(robot)
        L = len(robot.link_names)
        starts = groups[0] if groups is not None else np.arange(L)
        group = np.searchsorted(starts, np.arange(L), side="right") - 1
        G = len(starts)
        by_link = starts if groups is not None else None
        Q = np.random.default_rng(0).uniform(
            robot.lower, robot.upper, size=(args.states, robot.dof)
        )
        t: dict[str, float] = {}
        worst = 0.0
        with SimWorld(robot, problem.scene) as w:
            for q in Q:
                w.set_state(q)
                p0 = _timed(t, "self whole", _self, w, dmax, group, G, True)
                p1 = _timed(t, "self pairs", _self, w, dmax, group, G, False)
                s0 = _timed(t, "scene whole", _scene, w, dmax, group, G, True)
                s1 = _timed(t, "scene links", _scene, w, dmax, group, G, False)
                ld = _timed(t, "link_distances", w.link_distances, dmax, by_link)
                fin = np.isfinite(ld[2])
                worst = max(
                    worst,
                    float(np.max(np.abs(p0 - p1))),
                    float(np.max(np.abs(s0 - s1))),
                    float(np.max(np.abs(np.minimum(p0, dmax)[fin] - ld[2][fin]), initial=0.0)),
                )
        n = len(Q)
        print(
            f"{problem.name:20s} {L:4d} capsules, {G:3d} links | "
            + " | ".join(f"{k} {v / n * 1e3:.2f}" for k, v in t.items())
            + f" | self whole/pairs {t['self whole'] / t['self pairs']:.1f}x, scene whole/links "
            f"{t['scene whole'] / t['scene links']:.1f}x | largest difference {worst:.1e} m",
            flush=True,
        )
    print(f"load average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
