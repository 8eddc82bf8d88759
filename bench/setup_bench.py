"""Do the planners' set-ups stay inside the time limit on a thin chain? (issue 26, point 4)

Usage:

    PYTHONPATH=. python bench/setup_bench.py [LIMIT_S] [RADIUS_M,...]

Defaults: 2 s; radii 1 mm and 0.1 mm. The robot is a planar URDF chain of 10 links 10 cm
long (the one tests/planners/test_setup_budget.py builds) before a wall with a slot. For
each radius it prints the clearance field's size (spheres, self pairs: capped at
``MAX_SPHERES``, where 0.4 r spacing would need 2 500 to 25 000 spheres) and its build time,
the leader's grid (voxels, edge), then every clearance and follow-the-leader planner's
wall time for leg 0 with only a time limit on the wall clock, as a ratio to the limit
(``over`` marks a ratio above 1.01 plus one 50 ms poll interval), with the machine's load.
Before the caps, ``gradient.clearance+detour`` spent 11-13 s building its field at 1 mm
and was still building after 110 s at 0.1 mm; ``gradient.follow_leader+random`` asked
for a grid of about 1e10 voxels.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path


def chain_files(folder: Path, radius_m: float, n_links: int = 10, link_m: float = 0.1) -> Path:
    parts = ['<?xml version="1.0"?>\n<robot name="thin_chain">']
    parts.append('<link name="base"><collision><geometry><sphere radius="0.002"/></geometry>')
    parts.append("</collision></link>")
    parent = "base"
    for i in range(n_links):
        x = 0.0 if i == 0 else link_m
        parts.append(
            f'<joint name="j{i}" type="revolute"><parent link="{parent}"/>'
            f'<child link="l{i}"/><origin xyz="{x} 0 0"/><axis xyz="0 0 1"/>'
            '<limit lower="-2.5" upper="2.5" effort="1" velocity="1"/></joint>'
            f'<link name="l{i}"><collision>'
            f'<origin xyz="{link_m / 2} 0 0" rpy="0 1.5707963267948966 0"/>'
            f'<geometry><cylinder radius="{radius_m}" length="{link_m}"/></geometry>'
            "</collision></link>"
        )
        parent = f"l{i}"
    parts.append(
        f'<joint name="tip_joint" type="fixed"><parent link="{parent}"/><child link="tip"/>'
        f'<origin xyz="{link_m} 0 0" rpy="0 1.5707963267948966 0"/></joint><link name="tip"/>'
    )
    parts.append("</robot>\n")
    (folder / "thin_chain.urdf").write_text("\n".join(parts), "utf-8")
    start = ", ".join(["0.25"] * n_links)
    toml = f"""
[problem]
name = "thin_chain"
[robot]
type = "urdf"
urdf = "thin_chain.urdf"
tip_link = "tip"
[start]
q = [{start}]
[checking]
joint_step = 0.02
[[obstacles]]
name = "wall_low"
type = "box"
center_m = [0.6, -0.3, 0.0]
size_m = [0.02, 0.5, 0.2]
[[obstacles]]
name = "wall_high"
type = "box"
center_m = [0.6, 0.35, 0.0]
size_m = [0.02, 0.5, 0.2]
[[goals]]
name = "behind"
p_m = [0.8, 0.3, 0.0]
n = [0.0, 1.0, 0.0]
pos_tol_m = 0.005
angle_tol_deg = 5.0
"""
    path = folder / "thin_chain.toml"
    path.write_text(toml, "utf-8")
    return path


def main(argv: list[str]) -> int:
    import numpy as np

    import plannerlab.planners.ompl  # noqa: F401 - loaded once, before any clock
    from plannerlab.collision.fcl_checker import problem_checker
    from plannerlab.planners import make_planner
    from plannerlab.planners.clearance import ClearanceField
    from plannerlab.planners.follow_leader.grid import grid_voxel_m, grid_voxels
    from plannerlab.problem.catalog import load_problem
    from plannerlab.problem.load import Budget

    limit_s = float(argv[0]) if argv else 2.0
    radii = [float(r) for r in argv[1].split(",")] if len(argv) > 1 else [1e-3, 1e-4]
    planners = [
        "gradient.clearance",
        "gradient.clearance+detour",
        "gradient.clearance+rrtconnect",
        "gradient.follow_leader",
        "gradient.follow_leader+random",
    ]
    print(f"load average {os.getloadavg()[0]:.1f}; limit {limit_s:g} s")
    worst = 0.0
    for radius in radii:
        with tempfile.TemporaryDirectory() as tmp:
            problem = load_problem(chain_files(Path(tmp), radius))
        problem_checker(problem)  # the collision core loaded before any clock
        t0 = time.perf_counter()
        field = ClearanceField(problem.robot, problem.scene, 0.01)
        build_s = time.perf_counter() - t0
        lengths = 10 * [0.1]
        want = sum(int(np.ceil(ln / (0.4 * radius))) + 1 for ln in lengths)
        extent = np.array([2.0, 2.0, 0.2])
        voxel = grid_voxel_m(extent, 0.5 * radius, 1_000_000)
        print(
            f"radius {radius * 1e3:g} mm: field {len(field._t)} spheres (0.4 r: {want}), "
            f"{len(field._self_a)} self pairs, built in {build_s:.3f} s; grid at half the "
            f"tip radius {grid_voxels(extent, 0.5 * radius):.2g} voxels, capped: edge "
            f"{voxel * 1e3:.1f} mm, {grid_voxels(extent, voxel):.2g} voxels"
        )
        for name in planners:
            planner = make_planner(name)
            t0 = time.perf_counter()
            r = planner.solve(problem, 0, Budget(time_limit_s=limit_s), np.random.default_rng(1))
            wall = time.perf_counter() - t0
            ratio = wall / limit_s
            worst = max(worst, ratio)
            over = "over" if wall > limit_s * 1.01 + 0.05 else ""
            print(f"  {name:32s} {r.status.value:17s} {wall:7.2f} s {ratio:6.2f} {over}")
    print(f"worst ratio {worst:.2f}; load average {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
