"""An independent referee of plans on a robot's real meshes (issue 27, point 7).

For each plan file: the problem's URDF is loaded in PyBullet *as it ships*
(``useFixedBase``, ``URDF_USE_SELF_COLLISION``; PyBullet resolves its ``package://``
paths itself), the scene's obstacles are added as collision shapes (boxes, cylinders,
spheres; a mesh obstacle from its file, scaled, as a concave triangle mesh), and every
leg's path is interpolated so that no joint moves more than ``--step`` rad (0.005), a
continuous joint the short way round (as a plan's edges are meant, ``docs/extending.md``;
which joints are continuous is read from the URDF's XML);
``getClosestPoints(robot, obstacle, 0.0)`` at every state; a negative distance is a
penetration. Joints off the planned chain stay at 0 (clipped into their limits), as
plannerlab freezes them. Only this script's own code and PyBullet decide; plannerlab is
used to read the plan and problem files.

    python bench/mesh_referee.py results/plans/*.json [--step 0.005]

Prints per leg: states checked, the smallest distance to the scene [mm] (at most 0:
touching; 100 mm: nothing within the query distance), and the verdict.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pybullet
from pybullet_utils.bullet_client import BulletClient
from scipy.spatial.transform import Rotation

from plannerlab.problem.catalog import load_problem
from plannerlab.problem.scene import Box, Cylinder, Sphere

QUERY_M = 0.1  # closest points reported up to this distance [m]


def _quat(T: np.ndarray) -> list[float]:
    return [float(v) for v in Rotation.from_matrix(T[:3, :3]).as_quat()]


def _shipped_urdf(path: Path, tmp: Path) -> Path:
    """The URDF without its visuals (only looks; a copy may lack their meshes), collision
    mesh paths made absolute: ``package://pkg/rest`` as ``folder/rest`` or
    ``folder/pkg/rest`` (PyBullet's own rule), relative paths from the URDF's folder."""
    folder = path.resolve().parent
    root = ET.parse(path).getroot()
    for link in root.iter("link"):
        for v in link.findall("visual"):
            link.remove(v)
        for m in link.iter("mesh"):
            fn = m.get("filename", "")
            if fn.startswith("package://"):
                rest = fn[len("package://") :]
                # the URDF's folder and its parents, as a ROS package path would hold it
                cands = [
                    b / r
                    for b in [folder, *list(folder.parents)[:4]]
                    for r in (rest, rest.partition("/")[2])
                ]
            else:
                cands = [folder / fn]
            m.set("filename", str(next((p for p in cands if p.is_file()), cands[0])))
    out = tmp / path.name
    out.write_text(ET.tostring(root, encoding="unicode"))
    return out


def referee(plan_file: Path, step: float) -> list[tuple[int, int, float, str]]:
    plan = json.loads(Path(plan_file).read_text())
    problem_file = Path(plan["problem_file"])
    if not problem_file.is_absolute():
        problem_file = (Path(plan_file).parent / problem_file).resolve()
        if not problem_file.is_file():
            problem_file = Path(plan["problem_file"]).resolve()
    problem = load_problem(problem_file)
    robot = problem.robot
    c = BulletClient(connection_mode=pybullet.DIRECT)
    T = np.asarray(robot.T_world_base)
    tmp = tempfile.TemporaryDirectory()
    body = c.loadURDF(
        str(_shipped_urdf(Path(robot.urdf_path), Path(tmp.name))),
        T[:3, 3].tolist(),
        _quat(T),
        useFixedBase=True,
        flags=pybullet.URDF_USE_SELF_COLLISION,
    )
    index = {c.getJointInfo(body, j)[1].decode(): j for j in range(c.getNumJoints(body))}
    joints = [index[n] for n in robot.joint_names]
    # top-level joints only (a <transmission> names joints too, without a type)
    urdf_root = ET.parse(robot.urdf_path).getroot()
    kind = {j.get("name"): j.get("type") for j in urdf_root.findall("joint")}
    continuous = np.array([kind.get(n) == "continuous" for n in robot.joint_names], dtype=bool)
    for j in range(c.getNumJoints(body)):  # joints off the chain: 0 within limits
        info = c.getJointInfo(body, j)
        if j not in joints and info[2] != pybullet.JOINT_FIXED:
            c.resetJointState(body, j, float(np.clip(0.0, info[8], info[9])))
    obstacles = []
    for o in problem.scene.obstacles:
        if getattr(o, "cover_of", ""):
            continue
        if isinstance(o, Box):
            shape = c.createCollisionShape(pybullet.GEOM_BOX, halfExtents=(o.size_m / 2).tolist())
        elif isinstance(o, Cylinder):
            shape = c.createCollisionShape(
                pybullet.GEOM_CYLINDER, radius=o.radius_m, height=o.length_m
            )
        elif isinstance(o, Sphere):
            shape = c.createCollisionShape(pybullet.GEOM_SPHERE, radius=o.radius_m)
        To = o.T_world_obstacle
        obstacles.append((o.name, c.createMultiBody(0.0, shape, -1, To[:3, 3].tolist(), _quat(To))))
    for m in problem.scene.meshes:
        shape = c.createCollisionShape(
            pybullet.GEOM_MESH,
            fileName=m.file,
            meshScale=np.asarray(m.scale).tolist(),
            flags=pybullet.GEOM_FORCE_CONCAVE_TRIMESH,
        )
        To = m.T_world_obstacle
        obstacles.append((m.name, c.createMultiBody(0.0, shape, -1, To[:3, 3].tolist(), _quat(To))))
    root = c.getBodyInfo(body)[0].decode()
    fixed_links = {-1} | {
        j for j in range(c.getNumJoints(body)) if c.getJointInfo(body, j)[12].decode() == root
    }
    out = []
    for leg in plan["legs"]:
        path = np.asarray(leg["path"], dtype=float)
        if len(path) == 0:
            out.append((leg["leg"], 0, float("nan"), "no path"))
            continue
        states = [path[:1]]
        for a, b in zip(path[:-1], path[1:], strict=True):
            d = b - a  # a continuous joint the short way round
            d = np.where(continuous, (d + np.pi) % (2 * np.pi) - np.pi, d)
            n = max(1, int(np.ceil(np.max(np.abs(d)) / step)))
            states.append(a + d * (np.arange(1, n + 1)[:, None] / n))
        Q = np.concatenate(states)
        best, where = QUERY_M, ""
        for q in Q:
            for j, v in zip(joints, q, strict=True):
                c.resetJointState(body, j, float(v))
            for name, uid in obstacles:
                for pt in c.getClosestPoints(body, uid, QUERY_M):
                    if pt[3] in fixed_links:
                        continue
                    if pt[8] < best:
                        link = c.getJointInfo(body, pt[3])[12].decode()
                        best, where = float(pt[8]), f"{link} x {name}"
        verdict = "clean" if best > 0 else f"PENETRATION {where}"
        out.append(
            (
                leg["leg"],
                len(Q),
                best,
                verdict + (f" (closest {where})" if best > 0 and where else ""),
            )
        )
    c.disconnect()
    tmp.cleanup()
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("plans", nargs="+", type=Path)
    ap.add_argument("--step", type=float, default=0.005, help="joint step [rad]")
    args = ap.parse_args()
    bad = 0
    for f in args.plans:
        for leg, n, d, verdict in referee(f, args.step):
            print(f"{f.name} leg {leg}: {n} states, min distance {d * 1e3:.2f} mm, {verdict}")
            bad += not verdict.startswith("clean")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
