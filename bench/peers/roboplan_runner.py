"""roboplan's RRT-Connect on one joint-to-joint query of ``bench/peers_mesh.py`` (run in
roboplan's own virtual environment: ``python roboplan_runner.py QUERY.json OUT.json``;
the query and answer formats: ``common.py``).

roboplan 0.7.0 (Pinocchio + Coal): ``loadUrdfSceneDescription`` on the query's
``urdf_absolute`` (Pinocchio does not resolve a mesh path relative to the URDF's folder),
``importSrdf`` (disabled pairs); the obstacles added to the scene on ``universe`` (boxes,
cylinders, spheres; a mesh obstacle as ``core.Mesh(file, scale)``, Coal's triangles), and
their pairs among themselves disabled (roboplan checks obstacles against each other too);
``setRngSeed(seed)``. The search: ``rrt.RRT`` with ``rrt_connect``, ``max_connection_distance``
= the query's ``range_rad``, ``collision_check_step_size`` = its ``joint_step_rad``,
``max_planning_time`` = its ``time_limit_s`` and ``max_nodes`` raised so the time governs;
then ``PathShortcutter`` (the same step, the same seed). ``plan_s`` is both.

roboplan refuses a URDF in which a joint and a link have one name ("Frame name ... was
already added to the map": the Unitree Z1's fixed joint ``gripperStator``). A *fixed*
joint's name names nothing a planner uses, so then the runner loads a copy with each such
fixed joint renamed ``<name>__joint`` and says so in ``notes``; a movable joint so named
stays refused.
"""

from __future__ import annotations

import importlib.metadata
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np
from common import main, reorder


def renamed_fixed_joints(urdf: str) -> tuple[str, list[str]]:
    """A copy of ``urdf`` (beside it) whose fixed joints named like a link are renamed
    ``<name>__joint``; the names renamed (none: ``urdf`` itself)."""
    root = ET.parse(urdf).getroot()
    links = {e.get("name") for e in root.iter("link")}
    renamed = []
    for j in root.iter("joint"):
        if j.get("name") in links and j.get("type") == "fixed":
            renamed.append(str(j.get("name")))
            j.set("name", f"{j.get('name')}__joint")
    if not renamed:
        return urdf, []
    out = Path(urdf).with_name(Path(urdf).stem + "_roboplan.urdf")
    out.write_text(ET.tostring(root, encoding="unicode"))
    return str(out), renamed


def solve(query: dict[str, Any]) -> dict[str, Any]:
    from roboplan import core, rrt

    notes: list[str] = []
    t0 = time.perf_counter()
    desc = core.loadUrdfSceneDescription(query["urdf_absolute"], [])
    try:
        scene = core.Scene("peers_mesh", desc)
    except RuntimeError as exc:
        urdf, renamed = renamed_fixed_joints(query["urdf_absolute"])
        if not renamed:
            raise
        notes.append(
            f"refused the URDF ({exc}); loaded with the fixed joint(s) "
            f"{', '.join(renamed)} renamed <name>__joint"
        )
        scene = core.Scene("peers_mesh", core.loadUrdfSceneDescription(urdf, []))
    with open(query["srdf"]) as fh:
        scene.importSrdf(fh.read())
    names = list(scene.getJointNames())
    to_query = reorder(names, query["joint_names"])
    to_scene = reorder(query["joint_names"], names)
    color = np.array([0.5, 0.5, 0.5, 1.0])
    added = []
    for o in query["obstacles"]:
        T = np.asfortranarray(np.asarray(o["T_world_obstacle"], dtype=float))
        name = o["name"]
        if o["type"] == "box":
            scene.addBoxGeometry(name, "universe", core.Box(*map(float, o["size_m"])), T, color)
        elif o["type"] == "cylinder":
            geom = core.Cylinder(float(o["radius_m"]), float(o["length_m"]))
            scene.addCylinderGeometry(name, "universe", geom, T, color)
        elif o["type"] == "sphere":
            scene.addSphereGeometry(name, "universe", core.Sphere(float(o["radius_m"])), T, color)
        else:
            mesh = core.Mesh(o["file"], np.asarray(o["scale"], dtype=float))
            scene.addMeshGeometry(name, "universe", mesh, T, color)
        added.append(name)
    pairs = [(a, b) for k, a in enumerate(added) for b in added[k + 1 :]]
    if pairs:
        scene.setCollisions(pairs, False)
    scene.setRngSeed(int(query["seed"]))
    setup_s = time.perf_counter() - t0
    q0 = np.asarray(query["q_start"], dtype=float)[to_scene]
    qg = np.asarray(query["q_goal"], dtype=float)[to_scene]
    # Pinocchio holds a continuous joint as (cos, sin): the scene takes the expanded vector
    q0 = core.expandContinuousJointPositions(scene, "", q0)
    qg = core.expandContinuousJointPositions(scene, "", qg)
    start_valid = not scene.hasCollisions(q0)
    goal_valid = not scene.hasCollisions(qg)
    if not start_valid:
        notes.append("start in collision in roboplan's model")
    if not goal_valid:
        notes.append("goal in collision in roboplan's model")
    opts = rrt.RRTOptions()
    opts.rrt_connect = True
    opts.max_connection_distance = float(query["range_rad"])
    opts.collision_check_step_size = float(query["joint_step_rad"])
    opts.max_planning_time = float(query["time_limit_s"])
    opts.max_nodes = 10**7
    planner = rrt.RRT(scene, opts)
    t1 = time.perf_counter()
    try:
        path = planner.plan(core.JointConfiguration(names, q0), core.JointConfiguration(names, qg))
        short = core.PathShortcutter(
            scene,
            core.PathShortcuttingOptions(
                max_step_size=float(query["joint_step_rad"]), seed=int(query["seed"])
            ),
        )
        P = np.asarray(short.shortcut(path).positions, dtype=float)
        if P.ndim == 2 and P.shape[1] != len(names):  # expanded continuous joints
            P = np.array([core.collapseContinuousJointPositions(scene, "", p) for p in P])
        solved, status = len(P) >= 2, "solved"
    except Exception as exc:  # roboplan raises when it finds no path in its time
        P, solved, status = np.zeros((0, len(names))), False, f"{type(exc).__name__}: {exc}"
    plan_s = time.perf_counter() - t1
    if solved and P.shape[1] != len(names):
        raise SystemExit(f"roboplan's path has {P.shape[1]} columns for joints {names}")
    return {
        "version": importlib.metadata.version("roboplan"),
        "solved": bool(solved),
        "status": status[:600],
        "setup_s": setup_s,
        "plan_s": plan_s,
        "start_valid": start_valid,
        "goal_valid": goal_valid,
        "path": P[:, to_query].tolist() if solved else [],
        "notes": notes,
    }


if __name__ == "__main__":
    raise SystemExit(main("roboplan", solve))
