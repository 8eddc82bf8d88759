"""plannerlab beside MPlib and roboplan on one mesh robot, every path refereed on the meshes.

The robot: PyBullet's Franka Panda as it ships (``pybullet_data/franka_panda/panda.urdf``,
its collision meshes), its two finger joints made fixed, open at 0.04 m (the peers would
otherwise plan 9 joints; MotionBenchMaker's goals grasp around a can, which closed fingers
go through): one derived URDF (see :func:`derived_urdf`), given to both peers, to the
referee and, with ``--plannerlab-geometry mesh``, to plannerlab. The SRDF: MotionBenchMaker's
``panda.srdf`` (MoveIt's, for the same links). The scenes, starts and goals: the first
``--n`` problems of MotionBenchMaker's Panda ``box`` scenario (an open box of boxes on a
table; the vamp-planner 0.6.4 sdist through pip, see ``plannerlab import mbm --fetch``).

plannerlab plans on ``--plannerlab-geometry``: ``spherized`` (MotionBenchMaker's spherized
Panda, the default, as plannerlab could not load meshes before the ``mesh`` branch) or
``mesh`` (the derived mesh URDF itself; needs a plannerlab that loads collision meshes).

Each planner gets ``--time-limit`` (10 s) per problem and the same RRT-Connect range (OMPL's
default for the Panda's limits, 20 % of the joint-limit box's diagonal: 2.683 rad):

* plannerlab ``ompl.rrtconnect``: planning time = the leg's ``time_s``; whole call = ``solve``
  (checker built, RRT-Connect, simplification, interpolation, re-check, clearance);
* MPlib 0.2.1 (its own venv, numpy < 2): planning time = ``planner.planner.plan`` (OMPL
  RRT-Connect + simplification); whole call = ``plan_qpos`` (the same plus TOPP-RA retiming),
  run separately on the same problem; the obstacles as FCL primitives, the scene's
  allowed pairs in its ACM;
* roboplan (its own venv): planning time = ``RRT.plan`` (RRT-Connect, ``max_nodes`` raised
  so the time limit governs, ``collision_check_step_size`` = plannerlab's ``joint_step``
  0.02 rad) + ``PathShortcutter.shortcut``; whole call = the obstacles added + both (a
  fresh scene per problem, its URDF load not timed: see ``roboplan_worker``);
  the obstacles as Coal primitives (their pairs among themselves disabled: roboplan checks
  them too, and the box's walls touch), the SRDF imported.

The referee (PyBullet, this process; nothing of plannerlab's checking): the derived URDF
loaded with ``useFixedBase`` and ``URDF_USE_SELF_COLLISION``, each obstacle a collision
shape; every path cut so that no joint moves more than ``--referee-step`` (0.005 rad);
``getClosestPoints(robot, obstacle, 0.0)`` at every state; a negative distance is a
penetration and the path is not counted solved. Robot against scene only (self-collision
is not refereed). The paths' ends are compared with the start and goal. PyBullet collides
each link's convex hull; at the deepest state of a path it refuses, python-fcl on the mesh
triangles gives a second opinion (intersect, or how far apart), printed beside it.

    PYTHONPATH=. .venv/bin/python bench/peers_mesh_bench.py [--n 5] [--time-limit 10]
        [--plannerlab-geometry spherized|mesh] [--peers ~/.cache/plannerlab-peers]

Set-up of the peers' venvs (PyPI only)::

    python3 -m venv ~/.cache/plannerlab-peers/mplib
    ~/.cache/plannerlab-peers/mplib/bin/pip install mplib==0.2.1 'numpy<2'
    python3 -m venv ~/.cache/plannerlab-peers/roboplan
    ~/.cache/plannerlab-peers/roboplan/bin/pip install roboplan
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

REFEREE_QUERY_M = 0.0
#: the mesh Panda's finger joints are fixed open (their upper limit): MotionBenchMaker's
#: goals are grasps around a can, closed fingers (0) go through it
FINGER_M = 0.04


# ---------------------------------------------------------------------- peers (own venvs)
def _box_T(o: dict[str, Any]) -> Any:
    import numpy as np

    T = np.eye(4)
    T[:3, :3] = np.array(o["R"])
    T[:3, 3] = o["p"]
    return T


def mplib_worker(spec: dict[str, Any]) -> dict[str, Any]:
    import mplib
    import numpy as np
    from mplib.collision_detection import fcl as mfcl

    t_build = time.perf_counter()
    planner = mplib.Planner(urdf=spec["urdf"], srdf=spec["srdf"], move_group=spec["tip_link"])
    build_s = time.perf_counter() - t_build
    world = planner.planning_world
    acm = world.get_allowed_collision_matrix()
    runs = []
    for prob in spec["problems"]:
        names, pairs = [], []
        for k, o in enumerate(prob["obstacles"]):
            if o["type"] == "box":
                geom = mfcl.Box(o["size"])
            elif o["type"] == "cylinder":
                geom = mfcl.Cylinder(o["size"][0], o["size"][1])
            else:
                geom = mfcl.Sphere(o["size"][0])
            name = f"obstacle{k}"
            pose = mplib.Pose(o["p"], o["q_wxyz"])
            world.add_object(
                mfcl.FCLObject(name, pose, [mfcl.CollisionObject(geom)], [mplib.Pose()])
            )
            names.append(name)
        for a, b in prob["allowed"]:
            acm.set_entry(a, b, True)
            pairs.append((a, b))
        q0, qg = np.array(prob["q_start"]), np.array(prob["q_goal"])
        planner.robot.set_qpos(planner.pad_move_group_qpos(q0), True)
        t0 = time.perf_counter()
        status, path = planner.planner.plan(
            q0, [qg], time=spec["time_limit_s"], range=spec["range"], simplify=True
        )
        plan_s = time.perf_counter() - t0
        planner.robot.set_qpos(planner.pad_move_group_qpos(q0), True)
        t0 = time.perf_counter()
        res = planner.plan_qpos(
            [qg], q0, rrt_range=spec["range"], planning_time=spec["time_limit_s"]
        )
        whole_s = time.perf_counter() - t0
        solved = status == "Exact solution"
        runs.append(
            {
                "name": prob["name"],
                "solved": solved,
                "status": str(status),
                "plan_s": plan_s,
                "whole_s": whole_s,
                "whole_status": str(res.get("status")),
                "path": np.asarray(path).tolist() if solved else [],
            }
        )
        for n in names:
            world.remove_object(n)
        for a, b in pairs:
            acm.remove_entry(a, b)
    return {"version": mplib.__version__, "build_s": build_s, "runs": runs}


def roboplan_worker(spec: dict[str, Any]) -> dict[str, Any]:
    import importlib.metadata

    import numpy as np
    from roboplan import core, rrt

    # Pinocchio does not resolve a relative mesh path from the URDF's folder: the same
    # file with the same meshes named by absolute paths
    src = Path(spec["urdf"])
    text = src.read_text().replace('filename="meshes/', f'filename="{src.parent}/meshes/')
    urdf = src.with_name(src.stem + "_abs.urdf")
    urdf.write_text(text)
    build_s = 0.0
    runs = []
    for i, prob in enumerate(spec["problems"]):
        # a scene of its own per problem: obstacles removed and added again under the same
        # names were not checked against the robot any more (its own hasCollisions passed
        # states where a fresh scene finds the hand inside a wall)
        t_build = time.perf_counter()
        desc = core.loadUrdfSceneDescription(str(urdf), [])
        scene = core.Scene("peers", desc)
        scene.importSrdf(Path(spec["srdf"]).read_text())
        names_q = list(scene.getJointNames())
        build_s += time.perf_counter() - t_build
        if names_q != prob["joint_names"]:
            raise SystemExit(f"roboplan's joints {names_q} != {prob['joint_names']}")
        t_whole = time.perf_counter()
        added, pairs = [], []
        for k, o in enumerate(prob["obstacles"]):
            name = f"obstacle{k}"
            T = np.asfortranarray(_box_T(o))
            color = np.array([0.5, 0.5, 0.5, 1.0])
            if o["type"] == "box":
                scene.addBoxGeometry(name, "universe", core.Box(*o["size"]), T, color)
            elif o["type"] == "cylinder":
                scene.addCylinderGeometry(
                    name, "universe", core.Cylinder(o["size"][0], o["size"][1]), T, color
                )
            else:
                scene.addSphereGeometry(name, "universe", core.Sphere(o["size"][0]), T, color)
            added.append(name)
        # roboplan checks obstacles against each other too (the box's walls touch)
        pairs += [(a, b) for k, a in enumerate(added) for b in added[k + 1 :]]
        for a, b in prob["allowed"]:
            pairs.append((a, b))
        if pairs:
            scene.setCollisions(pairs, False)
        scene.setRngSeed(i + 1)
        opts = rrt.RRTOptions()
        opts.rrt_connect = True
        opts.max_connection_distance = spec["range"]
        opts.collision_check_step_size = spec["joint_step"]
        opts.max_planning_time = spec["time_limit_s"]
        opts.max_nodes = 10**7
        planner = rrt.RRT(scene, opts)
        q0 = core.JointConfiguration(names_q, np.array(prob["q_start"]))
        qg = core.JointConfiguration(names_q, np.array(prob["q_goal"]))
        t0 = time.perf_counter()
        status = "ok"
        try:
            path = planner.plan(q0, qg)
            P = np.asarray(path.positions)
            short = core.PathShortcutter(
                scene, core.PathShortcuttingOptions(max_step_size=spec["joint_step"], seed=i + 1)
            )
            P = np.asarray(short.shortcut(path).positions)
            solved = len(P) >= 2
            if spec.get("debug"):
                raw = np.asarray(path.positions)
                for label, Q in (("raw", raw), ("shortcut", P)):
                    bad = [
                        k
                        for k in range(len(Q) - 1)
                        if core.hasCollisionsAlongPath(scene, Q[k], Q[k + 1], 0.005)
                    ]
                    print(
                        f"{prob['name']} {label}: {len(Q)} states, edges in collision {bad}",
                        file=sys.stderr,
                    )
        except Exception as exc:  # roboplan raises when it finds no path
            status, P, solved = f"{type(exc).__name__}: {exc}"[:200], np.zeros((0, 7)), False
        plan_s = time.perf_counter() - t0
        whole_s = time.perf_counter() - t_whole
        runs.append(
            {
                "name": prob["name"],
                "solved": solved,
                "status": status,
                "plan_s": plan_s,
                "whole_s": whole_s,
                "path": P.tolist() if solved else [],
            }
        )
    return {"version": importlib.metadata.version("roboplan"), "build_s": build_s, "runs": runs}


# ---------------------------------------------------------------------- the derived URDF
def derived_urdf(src: Path, out: Path, fixed_joints: dict[str, float]) -> Path:
    """``src`` with visuals removed and ``fixed_joints`` made fixed at the value given
    (their origins moved along their axes). Each collision mesh is copied beside ``out``
    (``meshes/<name>``) without its polyline (``l``) records: MPlib's loader refuses
    PyBullet's ``link6.obj`` for them ("a face with 2 vertices"); the triangles, the only
    solid, are the same."""
    import numpy as np

    folder = src.resolve().parent
    mesh_dir = out.parent / "meshes"
    mesh_dir.mkdir(parents=True, exist_ok=True)
    root = ET.parse(src).getroot()
    for link in root.iter("link"):
        for v in link.findall("visual"):
            link.remove(v)
        for m in link.iter("mesh"):
            fn = m.get("filename", "")
            rest = fn[len("package://") :] if fn.startswith("package://") else fn
            if not (folder / rest).is_file():
                raise SystemExit(f"{src}: mesh {fn} not found as {folder / rest}")
            lines = (folder / rest).read_text().splitlines()
            keep = [s for s in lines if not s.startswith(("l ", "mtllib", "usemtl"))]
            (mesh_dir / Path(rest).name).write_text("\n".join(keep) + "\n")
            m.set("filename", f"meshes/{Path(rest).name}")
    for j in root.iter("joint"):
        name = j.get("name")
        if name not in fixed_joints:
            continue
        axis = np.array([float(v) for v in j.find("axis").get("xyz").split()])
        origin = j.find("origin")
        xyz = np.array([float(v) for v in origin.get("xyz", "0 0 0").split()])
        rpy = [float(v) for v in origin.get("rpy", "0 0 0").split()]
        if any(abs(a) > 1e-12 for a in rpy):
            raise SystemExit(f"{src}: joint {name}: only unrotated origins are handled")
        origin.set("xyz", " ".join(repr(float(v)) for v in xyz + axis * fixed_joints[name]))
        j.set("type", "fixed")
        for tag in ("limit", "mimic", "axis", "dynamics", "safety_controller"):
            for e in j.findall(tag):
                j.remove(e)
    ET.ElementTree(root).write(out)
    return out


# ---------------------------------------------------------------------- the referee
class Referee:
    """PyBullet on the meshes: the smallest distance robot-scene along a path."""

    def __init__(self, urdf: Path, joint_names: list[str]) -> None:
        import pybullet
        from pybullet_utils.bullet_client import BulletClient

        self.pb = pybullet
        self.c = BulletClient(connection_mode=pybullet.DIRECT)
        self.robot = self.c.loadURDF(
            str(urdf), useFixedBase=True, flags=pybullet.URDF_USE_SELF_COLLISION
        )
        by_name = {
            self.c.getJointInfo(self.robot, j)[1].decode(): j
            for j in range(self.c.getNumJoints(self.robot))
        }
        self.joints = [by_name[n] for n in joint_names]
        self.link_names = {-1: self.c.getBodyInfo(self.robot)[0].decode()}
        for j in range(self.c.getNumJoints(self.robot)):
            self.link_names[j] = self.c.getJointInfo(self.robot, j)[12].decode()
        self.obstacles: list[int] = []

    def set_scene(self, obstacles: list[dict[str, Any]]) -> None:
        for b in self.obstacles:
            self.c.removeBody(b)
        self.obstacles = []
        for o in obstacles:
            if o["type"] == "box":
                shape = self.c.createCollisionShape(
                    self.pb.GEOM_BOX, halfExtents=[s / 2 for s in o["size"]]
                )
            elif o["type"] == "cylinder":
                shape = self.c.createCollisionShape(
                    self.pb.GEOM_CYLINDER, radius=o["size"][0], height=o["size"][1]
                )
            else:
                shape = self.c.createCollisionShape(self.pb.GEOM_SPHERE, radius=o["size"][0])
            w, x, y, z = o["q_wxyz"]
            self.obstacles.append(self.c.createMultiBody(0, shape, -1, o["p"], [x, y, z, w]))

    def min_distance_m(self, path: Any, step_rad: float) -> tuple[float, int]:
        """The smallest robot-obstacle distance along ``path`` (interpolated so no joint
        moves more than ``step_rad``; only contacts within 0 are reported, so 0 means
        nothing touches) and the number of states checked."""
        import numpy as np

        P = np.asarray(path, dtype=float)
        states = [P[0]]
        for a, b in zip(P[:-1], P[1:], strict=True):
            n = max(1, math.ceil(float(np.max(np.abs(b - a))) / step_rad))
            states += [a + (b - a) * (k / n) for k in range(1, n + 1)]
        worst, where, self.worst_q = 0.0, "", None
        for i, q in enumerate(states):
            self.c.resetJointStatesMultiDof(self.robot, self.joints, [[float(v)] for v in q])
            self.c.performCollisionDetection()
            for k, ob in enumerate(self.obstacles):
                for pt in self.c.getClosestPoints(self.robot, ob, REFEREE_QUERY_M):
                    if float(pt[8]) < worst:
                        worst = float(pt[8])
                        link = self.link_names.get(pt[3], "?")
                        where = f"state {i}/{len(states) - 1}: {link} x obstacle {k}"
                        self.worst_q = q
        return worst, len(states), where


class TriangleReferee:
    """A second opinion at one state: python-fcl on the mesh triangles themselves (BVH
    models of the derived URDF's collision meshes, placed by ``yourdfpy``'s forward
    kinematics), where PyBullet collides each link's convex hull. Whether a link and an
    obstacle intersect, else their distance."""

    def __init__(self, urdf: Path, joint_names: list[str]) -> None:
        import fcl
        import numpy as np
        import trimesh
        import yourdfpy

        self.fcl = fcl
        self.model = yourdfpy.URDF.load(
            str(urdf), build_scene_graph=True, load_meshes=False, load_collision_meshes=False
        )
        self.joint_names = joint_names
        self.links: list[tuple[str, Any, Any]] = []  # link, T_link_mesh, BVH
        for link in self.model.robot.links:
            for col in link.collisions:
                if col.geometry.mesh is None:
                    continue
                mesh = trimesh.load(
                    str(Path(urdf).parent / col.geometry.mesh.filename), force="mesh"
                )
                bvh = fcl.BVHModel()
                bvh.beginModel(len(mesh.vertices), len(mesh.faces))
                bvh.addSubModel(np.asarray(mesh.vertices), np.asarray(mesh.faces))
                bvh.endModel()
                T = np.eye(4) if col.origin is None else np.asarray(col.origin)
                self.links.append((link.name, T, bvh))

    def at(self, q: Any, obstacles: list[dict[str, Any]]) -> tuple[float, str]:
        """(smallest distance [m], 0 when some pair intersects; which pair)."""
        import numpy as np

        fcl = self.fcl
        self.model.update_cfg(dict(zip(self.joint_names, map(float, q), strict=True)))
        obs = []
        for o in obstacles:
            if o["type"] == "box":
                g = fcl.Box(*o["size"])
            elif o["type"] == "cylinder":
                g = fcl.Cylinder(o["size"][0], o["size"][1])
            else:
                g = fcl.Sphere(o["size"][0])
            obs.append(fcl.CollisionObject(g, fcl.Transform(np.array(o["R"]), np.array(o["p"]))))
        best, where = math.inf, ""
        for name, T_lm, bvh in self.links:
            T = self.model.get_transform(name) @ T_lm
            a = fcl.CollisionObject(bvh, fcl.Transform(T[:3, :3], T[:3, 3]))
            for k, b in enumerate(obs):
                if fcl.collide(a, b, fcl.CollisionRequest(), fcl.CollisionResult()):
                    return 0.0, f"{name} x obstacle {k} intersect"
                d = fcl.distance(a, b, fcl.DistanceRequest(), fcl.DistanceResult())
                if d < best:
                    best, where = d, f"{name} x obstacle {k}"
        return best, where


# ---------------------------------------------------------------------- the run
def spec_of(problem: Any, joint_names: list[str]) -> dict[str, Any]:
    import numpy as np
    from scipy.spatial.transform import Rotation

    from plannerlab.problem.scene import Box, Cylinder

    obstacles = []
    for o in problem.scene.obstacles:
        T = np.asarray(o.T_world_obstacle)
        if isinstance(o, Box):
            kind, size = "box", [float(v) for v in o.size_m]
        elif isinstance(o, Cylinder):
            kind, size = "cylinder", [float(o.radius_m), float(o.length_m)]
        else:
            kind, size = "sphere", [float(o.radius_m)]
        x, y, z, w = Rotation.from_matrix(T[:3, :3]).as_quat()
        obstacles.append(
            {
                "type": kind,
                "size": size,
                "p": T[:3, 3].tolist(),
                "R": T[:3, :3].tolist(),
                "q_wxyz": [float(w), float(x), float(y), float(z)],
            }
        )
    return {
        "name": problem.name,
        "joint_names": joint_names,
        "obstacles": obstacles,
        "allowed": [list(p) for p in problem.robot.allowed_collisions],
        "q_start": np.asarray(problem.q_start).tolist(),
        "q_goal": np.asarray(problem.goal(0).q_rad).tolist(),
    }


def run_peer(python: Path, which: str, spec: dict[str, Any], tmp: Path) -> dict[str, Any]:
    if not python.exists():
        return {"error": f"{python} not found (see the set-up in this script's docstring)"}
    spec_path = tmp / f"{which}.json"
    spec_path.write_text(json.dumps(spec))
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    t0 = time.perf_counter()
    done = subprocess.run(
        [str(python), __file__, "--worker", which, str(spec_path)],
        capture_output=True,
        text=True,
        env=env,
        check=False,
        timeout=60 + 3 * spec["time_limit_s"] * len(spec["problems"]),
    )
    wall = time.perf_counter() - t0
    lines = [s for s in done.stdout.splitlines() if s.startswith("{")]
    if spec.get("debug"):
        print(done.stderr[-3000:])
    if done.returncode != 0 or not lines:
        return {"error": f"exit {done.returncode}: {done.stderr.strip()[-1500:]}"}
    out = json.loads(lines[-1])
    out["process_s"] = wall
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--n", type=int, default=5, help="problems of the box scenario")
    ap.add_argument("--scenario", default="box")
    ap.add_argument("--time-limit", type=float, default=10.0, help="per problem [s]")
    ap.add_argument("--referee-step", type=float, default=0.005, help="[rad]")
    ap.add_argument("--plannerlab-geometry", choices=("spherized", "mesh"), default="spherized")
    ap.add_argument(
        "--cover-excess-m",
        type=float,
        default=None,
        help="with --plannerlab-geometry mesh: [robot] cover_excess_m of the problem files",
    )
    ap.add_argument(
        "--cover-max-spheres",
        type=int,
        default=None,
        help="with --plannerlab-geometry mesh: [robot] cover_max_spheres of the problem files",
    )
    ap.add_argument("--peers", type=Path, default=Path.home() / ".cache" / "plannerlab-peers")
    ap.add_argument("--json", type=Path, default=None, help="write everything here")
    ap.add_argument("--worker", nargs=2, help=argparse.SUPPRESS)
    ap.add_argument("--debug", action="store_true", help="peers re-check their own paths")
    args = ap.parse_args()
    if args.worker:
        which, spec_path = args.worker
        spec = json.loads(Path(spec_path).read_text())
        fn = mplib_worker if which == "mplib" else roboplan_worker
        print(json.dumps(fn(spec)))
        return

    import numpy as np
    import pybullet_data

    from plannerlab.planners import make_planner
    from plannerlab.problem import mbm
    from plannerlab.problem.load import Budget, parse_problem

    load0 = os.getloadavg()[0]
    # a plannerlab from before the UR5 and Fetch import has only the Panda's fetch
    got = mbm.fetch_vamp("panda") if hasattr(mbm, "fetch_vamp") else mbm.fetch_vamp_panda()
    mesh_src = Path(pybullet_data.getDataPath()) / "franka_panda" / "panda.urdf"
    tmp = Path(tempfile.mkdtemp(prefix="plannerlab_peers_"))
    fingers = {"panda_finger_joint1": FINGER_M, "panda_finger_joint2": FINGER_M}
    urdf = derived_urdf(mesh_src, tmp / "panda_mesh.urdf", fingers)
    pairs = mbm.problem_pairs(got.problems / f"{args.scenario}_panda")[: args.n]
    plannerlab_urdf = got.urdf if args.plannerlab_geometry == "spherized" else urdf
    problems = []
    for scene, request in pairs:
        out = tmp / f"{args.scenario}_{scene.stem.removeprefix('scene')}.toml"
        text = mbm.problem_toml(
            scene, request, out_path=out, urdf=plannerlab_urdf, srdf=got.srdf, tip_link="panda_hand"
        )
        extra = ""  # the mesh covers' [robot] keys
        if args.cover_excess_m is not None:
            extra += f"cover_excess_m = {args.cover_excess_m!r}\n"
        if args.cover_max_spheres is not None:
            extra += f"cover_max_spheres = {args.cover_max_spheres}\n"
        text = text.replace('tip_link = "panda_hand"\n', f'tip_link = "panda_hand"\n{extra}')
        out.write_text(text)
        problems.append(parse_problem(out))
    joint_names = list(problems[0].robot.joint_names)
    rrt_range = 0.2 * float(
        np.linalg.norm(np.asarray(problems[0].robot.upper) - np.asarray(problems[0].robot.lower))
    )
    spec = {
        "urdf": str(urdf),
        "srdf": str(got.srdf),
        "tip_link": "panda_hand",
        "time_limit_s": args.time_limit,
        "range": rrt_range,
        "joint_step": 0.02,
        "debug": args.debug,
        "problems": [spec_of(p, joint_names) for p in problems],
    }
    print(
        f"{len(problems)} problems ({args.scenario}_panda 1-{args.n}); mesh URDF {mesh_src} "
        f"(fingers fixed at {FINGER_M} m) for the peers and the referee; plannerlab on "
        f"{args.plannerlab_geometry} ({plannerlab_urdf.name}); RRT-Connect range "
        f"{rrt_range:.3f} rad; {args.time_limit} s each; referee step {args.referee_step} rad",
        flush=True,
    )

    results: dict[str, dict[str, Any]] = {}
    # plannerlab
    planner = make_planner("ompl.rrtconnect", {})
    budget = Budget(time_limit_s=args.time_limit)
    t_b = time.perf_counter()
    planner.solve(problems[0], 0, budget, np.random.default_rng(10**6))  # warm-up
    runs = []
    for i, p in enumerate(problems):
        t0 = time.perf_counter()
        r = planner.solve(p, 0, budget, np.random.default_rng(i))
        whole = time.perf_counter() - t0
        ok = r.status.name == "SOLVED"
        runs.append(
            {
                "name": p.name,
                "solved": ok,
                "status": r.status.name,
                "plan_s": r.time_s,
                "whole_s": whole,
                "path": np.asarray(r.path).tolist() if ok else [],
            }
        )
    results["plannerlab ompl.rrtconnect"] = {
        "version": f"{args.plannerlab_geometry} Panda",
        "build_s": time.perf_counter() - t_b,
        "runs": runs,
    }
    print("done: plannerlab", flush=True)
    for which in ("mplib", "roboplan"):
        got_peer = run_peer(args.peers / which / "bin" / "python", which, spec, tmp)
        label = "MPlib RRT-Connect" if which == "mplib" else "roboplan RRT-Connect"
        results[label] = got_peer
        print(f"done: {which}", flush=True)

    referee = Referee(urdf, joint_names)
    triangles = TriangleReferee(urdf, joint_names)
    by_name = {s["name"]: s for s in spec["problems"]}
    goal_tol = {p.name: p.goal(0).tol_rad for p in problems}
    for res in results.values():
        for r in res.get("runs", []):
            r["referee"] = ""
            if not r["solved"]:
                continue
            s = by_name[r["name"]]
            P = np.asarray(r["path"], dtype=float)
            if np.max(np.abs(P[0] - s["q_start"])) > 1e-6:
                r["referee"] = "does not start at the start"
            elif np.max(np.abs(P[-1] - s["q_goal"])) > goal_tol[r["name"]] + 1e-9:
                r["referee"] = "does not end at the goal"
            else:
                referee.set_scene(s["obstacles"])
                d, n, where = referee.min_distance_m(P, args.referee_step)
                r["referee_states"] = n
                if d < 0:
                    r["referee"] = f"penetrates {-d * 1e3:.1f} mm ({where})"
                    t_d, t_where = triangles.at(referee.worst_q, s["obstacles"])
                    r["triangles"] = (
                        f"{t_where}" if t_d == 0.0 else f"{t_d * 1e3:.2f} mm apart ({t_where})"
                    )
    load1 = os.getloadavg()[0]
    # one table
    base = results["plannerlab ompl.rrtconnect"]
    # times: the medians over every path a planner returned (refereed or not)
    base_ok = [r for r in base["runs"] if r["solved"]]
    base_plan = float(np.median([r["plan_s"] for r in base_ok])) if base_ok else float("nan")
    base_whole = float(np.median([r["whole_s"] for r in base_ok])) if base_ok else float("nan")
    print(
        f"\nload average {load0:.1f} at the start, {load1:.1f} at the end, {os.cpu_count()} cores"
    )
    print(
        "| planner | version | solved, refereed on meshes | failed the referee "
        "| of which triangles intersect (FCL) | median planning ms (paths returned) "
        "| planning / plannerlab | median whole call ms | whole / plannerlab |"
    )
    print("|" + "---|" * 9)
    for label, res in results.items():
        if "error" in res:
            print(f"| {label} | - | not run: {res['error'][-300:]} | | | | | | |")
            continue
        runs = res["runs"]
        ok = [r for r in runs if r["solved"] and not r["referee"]]
        bad = [r for r in runs if r["solved"] and r["referee"]]
        claimed = [r for r in runs if r["solved"]]
        mp = float(np.median([r["plan_s"] for r in claimed])) if claimed else float("nan")
        mw = float(np.median([r["whole_s"] for r in claimed])) if claimed else float("nan")
        print(
            f"| {label} | {res['version']} | {len(ok)}/{len(runs)} | {len(bad)} | "
            f"{sum('intersect' in r.get('triangles', '') for r in bad)} | "
            f"{mp * 1e3:.1f} | {mp / base_plan:.2f} | {mw * 1e3:.1f} | {mw / base_whole:.2f} |"
        )
    for label, res in results.items():
        for r in res.get("runs", []):
            extra = f" referee: {r['referee']}" if r.get("referee") else ""
            if r.get("triangles"):
                extra += f"; FCL on the triangles there: {r['triangles']}"
            n = r.get("referee_states", 0)
            print(
                f"  {label}: {r['name']}: {r['status']}, planning {r['plan_s'] * 1e3:.1f} ms, "
                f"whole {r['whole_s'] * 1e3:.1f} ms, {n} states refereed{extra}"
            )
        if "build_s" in res:
            print(f"  {label}: set-up (load + warm-up) {res['build_s']:.2f} s")
    if args.json:
        args.json.write_text(json.dumps(results))


if __name__ == "__main__":
    main()
