"""MPlib's RRT-Connect on one joint-to-joint query of ``bench/peers_mesh.py`` (run in
MPlib's own virtual environment: ``python mplib_runner.py QUERY.json OUT.json``; the
query and answer formats: ``common.py``).

MPlib 0.2.1: ``mplib.Planner`` loads the URDF (its collision meshes as FCL triangle
meshes, ``use_convex=False``, its default) and the query's SRDF (disabled pairs); the
obstacles are FCL objects in its planning world (boxes, cylinders, spheres; a mesh
obstacle by ``load_mesh_as_BVH``, scaled); ``mplib.set_global_seed(seed)``; the search is
``planner.planner.plan`` (OMPL RRT-Connect with ``range`` = the query's ``range_rad``,
``time`` = its ``time_limit_s``, simplification on): the goal is one joint state, so none
of ``plan_qpos``'s 2-pi copies of wide joints nor its TOPP-RA retiming. MPlib's motions
are checked at OMPL's default resolution (1 % of the state space's extent); it has no
setting for it in this call.

MPlib 0.2.1 refuses an arm with a continuous joint ("Do not support continuous revolute
joint for constrained planning", raised while the planner is built, whatever the query):
then the runner loads a copy whose continuous joints are revolute on [-pi, pi] (the range
plannerlab plans a continuous joint on) and says so in ``notes``.

MPlib prefixes a URDF's mesh paths with the URDF's folder, absolute ones too: the query's
``urdf_relative`` names the meshes relative to its own folder.
"""

from __future__ import annotations

import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
from common import main, reorder


def continuous_as_revolute(urdf: str) -> tuple[str, list[str]]:
    """A copy of ``urdf`` (beside it, so its relative mesh paths hold) whose continuous
    joints are revolute on [-pi, pi]; their names."""
    root = ET.parse(urdf).getroot()
    changed = []
    for j in root.iter("joint"):
        if j.get("type") == "continuous":
            changed.append(str(j.get("name")))
            j.set("type", "revolute")
            lim = j.find("limit")
            if lim is None:
                lim = ET.SubElement(j, "limit", effort="1", velocity="1")
            lim.set("lower", repr(-np.pi))
            lim.set("upper", repr(np.pi))
    out = Path(urdf).with_name(Path(urdf).stem + "_mplib.urdf")
    out.write_text(ET.tostring(root, encoding="unicode"))
    return str(out), changed


def solve(query: dict[str, Any]) -> dict[str, Any]:
    import mplib
    from mplib.collision_detection import fcl as mfcl

    notes: list[str] = []
    mplib.set_global_seed(int(query["seed"]))
    t0 = time.perf_counter()
    urdf, tip = query["urdf_relative"], query["tip_link"]
    try:
        planner = mplib.Planner(urdf=urdf, srdf=query["srdf"], move_group=tip)
    except RuntimeError as exc:
        if "continuous" not in str(exc):
            raise
        urdf, changed = continuous_as_revolute(urdf)
        notes.append(
            f"refused the URDF ({exc}); loaded with the continuous joint(s) "
            f"{', '.join(changed)} revolute on [-pi, pi]"
        )
        planner = mplib.Planner(urdf=urdf, srdf=query["srdf"], move_group=tip)
    names = list(planner.user_joint_names)
    group = [names[i] for i in planner.move_group_joint_indices]
    to_group = reorder(query["joint_names"], group)
    to_query = reorder(group, query["joint_names"])
    world = planner.planning_world
    for o in query["obstacles"]:
        if o["type"] == "box":
            geom = mfcl.Box(np.asarray(o["size_m"], dtype=float))
        elif o["type"] == "cylinder":
            geom = mfcl.Cylinder(float(o["radius_m"]), float(o["length_m"]))
        elif o["type"] == "sphere":
            geom = mfcl.Sphere(float(o["radius_m"]))
        else:
            geom = mfcl.load_mesh_as_BVH(o["file"], np.asarray(o["scale"], dtype=float))
        pose = mplib.Pose(o["p_m"], o["q_wxyz"])
        world.add_object(
            mfcl.FCLObject(o["name"], pose, [mfcl.CollisionObject(geom)], [mplib.Pose()])
        )
    setup_s = time.perf_counter() - t0
    q0 = np.asarray(query["q_start"], dtype=float)[to_group]
    qg = np.asarray(query["q_goal"], dtype=float)[to_group]

    def collisions(q: Any) -> list[str]:
        planner.robot.set_qpos(planner.pad_move_group_qpos(q), True)
        return [f"{c.link_name1} x {c.link_name2}" for c in world.check_collision()]

    goal_hits = collisions(qg)
    start_hits = collisions(q0)  # the robot left at the start for the search
    if start_hits:
        notes.append(f"start in collision in MPlib's model: {', '.join(start_hits[:4])}")
    if goal_hits:
        notes.append(f"goal in collision in MPlib's model: {', '.join(goal_hits[:4])}")
    t1 = time.perf_counter()
    status, path = planner.planner.plan(
        q0,
        [qg],
        time=float(query["time_limit_s"]),
        range=float(query["range_rad"]),
        simplify=True,
    )
    plan_s = time.perf_counter() - t1
    solved = status == "Exact solution"
    P = np.asarray(path, dtype=float).reshape(-1, len(group)) if solved else np.zeros((0, 0))
    return {
        "version": mplib.__version__,
        "solved": bool(solved),
        "status": str(status),
        "setup_s": setup_s,
        "plan_s": plan_s,
        "start_valid": not start_hits,
        "goal_valid": not goal_hits,
        "path": P[:, to_query].tolist() if solved else [],
        "notes": notes,
    }


if __name__ == "__main__":
    raise SystemExit(main("mplib", solve))
