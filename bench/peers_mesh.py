"""plannerlab beside MPlib and roboplan on the arms bench's mesh problems, every path
refereed on the real meshes (issue 35: "side by side with roboplan and MPlib on the same
mesh problems").

For each arm of ``bench/mesh_arms_bench.py`` (``--arms``) and each of its problems
(table, shelf, made by that bench's :func:`make_problems`, seeded) and legs (``reach``,
``back``):

1. **the query.** plannerlab's own solve of the problem as the arms bench poses it
   (``--source-planner``, seed 0, ``--source-time-limit``) gives each leg's start and
   goal *joint* states (the ends of its solved path), so every planner below solves the
   same joint-to-joint query. The query is written twice: as a plannerlab problem (the
   arms bench's robot, scene and margin; the start; a joint goal, ``joint_tol_rad`` 1e-3)
   and as a neutral JSON for the peers (format below).
2. **the planners**, each with ``--time-limit`` and seed ``--seed``: plannerlab's
   ``native.rrtconnect`` and ``ompl.rrtconnect`` (``plannerlab.solve`` on the query's
   problem, in this process), MPlib and roboplan, each in its own virtual environment as
   a subprocess (``bench/peers/mplib_runner.py``, ``bench/peers/roboplan_runner.py``:
   they read the query JSON and write the path as JSON). The peers' RRT-Connect range is
   OMPL's default for the arm (20 % of the joint-limit box's diagonal), as
   ``ompl.rrtconnect`` uses; roboplan checks its edges every ``joint_step`` (the
   problem's, 0.05 rad), MPlib at OMPL's default resolution (it has no setting).
3. **the referee**: ``bench/mesh_referee.py`` (PyBullet on the URDF as it ships, the
   scene's boxes and meshes) on every returned path, cut so that no joint moves more than
   ``--referee-step`` (0.005 rad); each cut state is refereed on its own, so the row
   has the number of states that penetrate the scene (distance <= 0) and the smallest
   distance (100 mm: nothing within the referee's query distance). PyBullet collides each
   link's convex hull: at the deepest state of a path it refuses, python-fcl on the meshes'
   own triangles gives a second opinion (:func:`triangles_at`). Robot against the
   scene only: the referee does not judge self-collision. Each path's ends are compared
   with the query's (1e-6 rad at the start, 1e-3 rad at the goal).

Rows: ``OUT/rows.jsonl`` (rewritten whole and renamed on every row: atomic), one per arm
x problem x leg x planner; an interrupted run resumes (rows, plans and peers' answers on
disk are not redone). Progress and the load average on stderr; ``--report`` prints the
tables from the rows (a summary per planner, then every leg).

The query JSON (``OUT/queries/<arm>_<problem>_<leg>.json``)::

    {"format": "plannerlab.peers_mesh.query/1", "name", "arm", "urdf_as_shipped",
     "urdf_absolute" (the URDF without visuals, its meshes by absolute paths, the joints
     off plannerlab's chain fixed where plannerlab freezes them), "urdf_relative" (the
     same, meshes relative to its folder), "srdf" (plannerlab's excluded link pairs as
     <disable_collisions>), "tip_link", "joint_names", "continuous", "q_start",
     "q_goal", "time_limit_s", "seed", "range_rad", "joint_step_rad",
     "obstacles": [{"name", "type": box|cylinder|sphere|mesh, "p_m", "q_wxyz",
                    "T_world_obstacle" (4x4, in the robot's base frame), "size_m" (box),
                    "radius_m", "length_m" (cylinder, sphere), "file", "scale" (mesh)}]}

    PYTHONPATH=. nice -n 10 .venv/bin/python bench/peers_mesh.py \\
        --erd <example-robot-data 6.0.0>/robots --out /tmp/peers_mesh [--time-limit 10]
    PYTHONPATH=. .venv/bin/python bench/peers_mesh.py --out /tmp/peers_mesh --report

The peers' virtual environments (``--mplib``, ``--roboplan``; how to make them:
``results/peers.md``); a peer whose python is missing gets a row saying so.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import tomllib
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

PEERS = {"mplib": "mplib_runner.py", "roboplan": "roboplan_runner.py"}
PLANNERS = ("native.rrtconnect", "ompl.rrtconnect", "mplib", "roboplan")
DEFAULT_ARMS = "xarm6,kinova,so101,panda,z1,iiwa"
GOAL_TOL_RAD = 1e-3


def log(msg: str) -> None:
    print(f"[{time.strftime('%H:%M:%S')} load {os.getloadavg()[0]:.1f}] {msg}", file=sys.stderr)


def write_atomic(path: Path, text: str) -> None:
    """``text`` at ``path``: a temporary file in the same folder, renamed."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    with os.fdopen(fd, "w") as fh:
        fh.write(text)
    os.replace(tmp, path)


# ---------------------------------------------------------------- the robot for the peers
def _fixed_origin(joint: ET.Element, value: float) -> tuple[str, str]:
    """The origin (xyz, rpy) of ``joint`` made fixed at ``value`` (its motion folded in)."""
    from scipy.spatial.transform import Rotation

    def floats(tag: str, key: str, default: str) -> list[float]:
        el = joint.find(tag)
        return [float(v) for v in (default if el is None else el.get(key, default)).split()]

    xyz, rpy = floats("origin", "xyz", "0 0 0"), floats("origin", "rpy", "0 0 0")
    axis = np.array(floats("axis", "xyz", "1 0 0"))
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
    T[:3, 3] = xyz
    M = np.eye(4)
    if joint.get("type") == "prismatic":
        M[:3, 3] = axis / np.linalg.norm(axis) * value
    else:
        M[:3, :3] = Rotation.from_rotvec(axis / np.linalg.norm(axis) * value).as_matrix()
    T = T @ M
    rpy_new = Rotation.from_matrix(T[:3, :3]).as_euler("xyz")
    return " ".join(repr(float(v)) for v in T[:3, 3]), " ".join(repr(float(v)) for v in rpy_new)


def peer_urdfs(robot: Any, folder: Path) -> tuple[Path, Path]:
    """The URDF as it ships, for the peers: visuals removed (looks only), the joints off
    plannerlab's chain fixed at the values plannerlab freezes them at, the collision meshes
    plannerlab resolves named by absolute paths (one file) and relative to ``folder``
    (another). The meshes themselves are the shipped files."""
    from plannerlab.robots.urdf.meshes import resolve_mesh

    src = Path(robot.urdf_path)
    root = ET.parse(src).getroot()
    for link in root.iter("link"):
        for v in link.findall("visual"):
            link.remove(v)
    for j in root.iter("joint"):
        if j.get("name") in robot.frozen_joints:
            xyz, rpy = _fixed_origin(j, float(robot.frozen_joints[j.get("name")]))
            origin = j.find("origin")
            if origin is None:
                origin = ET.SubElement(j, "origin")
            origin.set("xyz", xyz)
            origin.set("rpy", rpy)
            j.set("type", "fixed")
            for tag in ("limit", "mimic", "axis", "dynamics", "safety_controller", "calibration"):
                for e in j.findall(tag):
                    j.remove(e)
    meshes = [
        (m, resolve_mesh(m.get("filename", ""), src, tuple(robot.mesh_paths), f"{src.name}"))
        for m in root.iter("mesh")
    ]
    out = []
    for kind in ("absolute", "relative"):
        for m, f in meshes:
            m.set("filename", str(f) if kind == "absolute" else os.path.relpath(f, folder))
        path = folder / f"{src.stem}_{kind}.urdf"
        write_atomic(path, ET.tostring(root, encoding="unicode"))
        out.append(path)
    return out[0], out[1]


def srdf_text(robot: Any) -> str:
    """plannerlab's self-collision exclusions as an SRDF: every URDF link pair all of whose
    primitive pairs plannerlab never checks (same body, adjacent bodies, the problem's
    SRDF and allowed pairs)."""
    links = list(robot.link_urdf_names)
    names = sorted(set(links))
    excluded = robot.excluded_pairs
    lines = [f'<robot name="{Path(robot.urdf_path).stem}">']
    for a_i, a in enumerate(names):
        for b in names[a_i + 1 :]:
            ia = [i for i, n in enumerate(links) if n == a]
            ib = [i for i, n in enumerate(links) if n == b]
            if all((min(i, j), max(i, j)) in excluded for i in ia for j in ib):
                lines.append(f'  <disable_collisions link1="{a}" link2="{b}" reason="plannerlab"/>')
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- queries
def obstacles_json(problem: Any) -> list[dict[str, Any]]:
    """The scene's obstacles in the robot's base frame: pose, and size or mesh file."""
    from scipy.spatial.transform import Rotation

    from plannerlab.problem.scene import Box, Cylinder, Sphere

    T_base_world = np.linalg.inv(np.asarray(problem.robot.T_world_base))
    out = []
    items = [o for o in problem.scene.obstacles if not getattr(o, "cover_of", "")]
    for o in [*items, *problem.scene.meshes]:
        T = T_base_world @ np.asarray(o.T_world_obstacle)
        x, y, z, w = Rotation.from_matrix(T[:3, :3]).as_quat()
        d: dict[str, Any] = {
            "name": o.name,
            "p_m": T[:3, 3].tolist(),
            "q_wxyz": [float(w), float(x), float(y), float(z)],
            "T_world_obstacle": T.tolist(),
        }
        if isinstance(o, Box):
            d.update(type="box", size_m=[float(v) for v in o.size_m])
        elif isinstance(o, Cylinder):
            d.update(type="cylinder", radius_m=float(o.radius_m), length_m=float(o.length_m))
        elif isinstance(o, Sphere):
            d.update(type="sphere", radius_m=float(o.radius_m))
        else:
            d.update(type="mesh", file=str(o.file), scale=[float(v) for v in o.scale])
        out.append(d)
    return out


def source_plan(problem_file: Path, planner: str, time_limit_s: float, out: Path) -> Any:
    """plannerlab's plan of the arms bench's problem (seed 0), saved and reused."""
    import plannerlab as pl

    f = out / "source" / f"{problem_file.stem}__{planner}.json"
    if f.is_file():
        return json.loads(f.read_text())
    log(f"source plan: {problem_file.stem} with {planner} ({time_limit_s} s)")
    problem = pl.load_problem(problem_file)
    plan = pl.solve(problem, planner, 0, budget=pl.Budget(time_limit_s=time_limit_s))
    tmp = f.with_suffix(".tmp.json")
    plan.save(tmp)
    os.replace(tmp, f)
    return json.loads(f.read_text())


def write_queries(
    problem_file: Path, plan: dict[str, Any], args: argparse.Namespace
) -> list[tuple[str, Path, Path]]:
    """Per solved leg of ``plan``: (leg name, the plannerlab problem, the peers' JSON)."""
    from mesh_arms_bench import _toml

    import plannerlab as pl

    qdir = args.out / "queries"
    doc = tomllib.loads(problem_file.read_text())
    problem = pl.load_problem(problem_file)
    robot = problem.robot
    arm = problem_file.stem.split("_")[0]
    udir = args.out / "urdf" / arm
    udir.mkdir(parents=True, exist_ok=True)
    urdf_abs, urdf_rel = peer_urdfs(robot, udir)
    srdf = udir / f"{Path(robot.urdf_path).stem}.srdf"
    write_atomic(srdf, srdf_text(robot))
    span = np.asarray(robot.upper) - np.asarray(robot.lower)
    out = []
    for leg in plan["legs"]:
        if leg["status"] != "solved" or not leg["path"]:
            log(f"{problem_file.stem} leg {leg['goal']}: {leg['status']} in the source plan")
            continue
        q0, qg = leg["path"][0], leg["path"][-1]
        name = f"{problem_file.stem}_{leg['goal']}"
        tdoc = {k: v for k, v in doc.items() if k not in ("start", "goals")}
        tdoc["problem"] = {"name": name, "description": f"{name}: the joint query of peers_mesh"}
        tdoc["start"] = {"q": q0}
        tdoc["goals"] = [{"name": leg["goal"], "q": qg, "joint_tol_rad": GOAL_TOL_RAD}]
        toml_file = qdir / f"{name}.toml"
        head = f"# made by bench/peers_mesh.py from {problem_file}\n"
        write_atomic(toml_file, head + _toml(tdoc))
        query = {
            "format": "plannerlab.peers_mesh.query/1",
            "name": name,
            "arm": arm,
            "urdf_as_shipped": str(robot.urdf_path),
            "urdf_absolute": str(urdf_abs),
            "urdf_relative": str(urdf_rel),
            "srdf": str(srdf),
            "tip_link": robot.tip_link,
            "joint_names": list(robot.joint_names),
            "continuous": [bool(c) for c in robot.continuous],
            "root_links": sorted({robot.link_urdf_names[i] for i in robot.fixed_links}),
            "q_start": q0,
            "q_goal": qg,
            "time_limit_s": args.time_limit,
            "seed": args.seed,
            "range_rad": 0.2 * float(np.linalg.norm(span)),
            "joint_step_rad": float(problem.joint_step),
            "obstacles": obstacles_json(problem),
        }
        json_file = qdir / f"{name}.json"
        write_atomic(json_file, json.dumps(query, indent=1))
        out.append((leg["goal"], toml_file, json_file))
    return out


# ---------------------------------------------------------------- planners
def run_plannerlab(toml_file: Path, planner: str, args: argparse.Namespace) -> dict[str, Any]:
    import plannerlab as pl

    problem = pl.load_problem(toml_file)
    t0 = time.perf_counter()
    plan = pl.solve(problem, planner, args.seed, budget=pl.Budget(time_limit_s=args.time_limit))
    whole_s = time.perf_counter() - t0
    leg = plan.legs[0]
    return {
        "version": f"plannerlab {pl.__version__}" if hasattr(pl, "__version__") else "plannerlab",
        "solved": bool(leg.solved),
        "status": f"{leg.status.value}: {leg.reason}"[:300],
        "plan_s": float(leg.time_s),
        "whole_s": whole_s,
        "checks": int(leg.collision_checks),
        "path": np.asarray(leg.path).tolist() if leg.solved else [],
        "notes": [],
    }


def run_peer(peer: str, json_file: Path, answer: Path, args: argparse.Namespace) -> dict[str, Any]:
    python = Path(getattr(args, peer))
    if not python.exists():
        return {"solved": False, "status": f"not run: {python} not found", "path": []}
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    t0 = time.perf_counter()
    try:
        done = subprocess.run(
            [str(python), str(HERE / "peers" / PEERS[peer]), str(json_file), str(answer)],
            capture_output=True,
            text=True,
            env=env,
            check=False,
            timeout=180 + 3 * args.time_limit,
        )
    except subprocess.TimeoutExpired:
        return {"solved": False, "status": "killed: the runner overran its guard", "path": []}
    whole_s = time.perf_counter() - t0
    if done.returncode != 0 or not answer.is_file():
        return {
            "solved": False,
            "status": f"runner exit {done.returncode}: {done.stderr.strip()[-600:]}",
            "path": [],
        }
    got = json.loads(answer.read_text())
    got["whole_s"] = whole_s
    return dict(got)


# ---------------------------------------------------------------- referee
def interpolate(P: np.ndarray, step_rad: float) -> np.ndarray:
    """``P`` cut so that no joint moves more than ``step_rad`` (mesh_referee's rule)."""
    states = [P[:1]]
    for a, b in zip(P[:-1], P[1:], strict=True):
        n = max(1, int(np.ceil(np.max(np.abs(b - a)) / step_rad)))
        states.append(a + (b - a) * (np.arange(1, n + 1)[:, None] / n))
    return np.concatenate(states)


def referee_path(toml_file: Path, P: np.ndarray, step_rad: float, tmp: Path) -> dict[str, Any]:
    """``bench/mesh_referee.py`` on every cut state of ``P`` (one single-state leg each):
    states, states penetrating, the smallest distance and where."""
    from mesh_referee import referee

    Q = interpolate(P, step_rad)
    plan_file = tmp / "referee_plan.json"
    legs = [{"leg": i, "path": [q.tolist()]} for i, q in enumerate(Q)]
    plan_file.write_text(json.dumps({"problem_file": str(toml_file), "legs": legs}))
    got = referee(plan_file, step_rad)
    d = np.array([g[2] for g in got])
    worst = int(np.argmin(d))
    return {
        "referee_states": len(Q),
        "penetrating_states": int(np.sum(d <= 0)),
        "referee_min_mm": round(float(d[worst]) * 1e3, 2),
        "referee_where": got[worst][3],
        "worst_state": worst,
    }


def triangles_at(query: dict[str, Any], q: np.ndarray) -> str:
    """A second opinion at one state (PyBullet collides each link's convex hull): python-fcl
    on the collision meshes' own triangles (and the URDF's primitives), placed by
    yourdfpy's kinematics of the peers' URDF, against the scene (a mesh obstacle as its
    triangles): the pair that intersects, else the smallest distance. Links on the root
    body are skipped, as the referee skips them."""
    import fcl
    import trimesh
    import yourdfpy

    urdf = Path(query["urdf_relative"])
    model = yourdfpy.URDF.load(
        str(urdf), build_scene_graph=True, load_meshes=False, load_collision_meshes=False
    )
    model.update_cfg(dict(zip(query["joint_names"], map(float, q), strict=True)))

    def bvh(mesh: Any) -> Any:
        m = fcl.BVHModel()
        m.beginModel(len(mesh.vertices), len(mesh.faces))
        m.addSubModel(np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces))
        m.endModel()
        return m

    def placed(geom: Any, T: np.ndarray) -> Any:
        return fcl.CollisionObject(geom, fcl.Transform(T[:3, :3], T[:3, 3]))

    scene = []
    for o in query["obstacles"]:
        if o["type"] == "box":
            g = fcl.Box(*o["size_m"])
        elif o["type"] == "cylinder":
            g = fcl.Cylinder(o["radius_m"], o["length_m"])
        elif o["type"] == "sphere":
            g = fcl.Sphere(o["radius_m"])
        else:
            g = bvh(trimesh.load(o["file"], force="mesh").apply_scale(o["scale"]))
        scene.append((o["name"], placed(g, np.asarray(o["T_world_obstacle"]))))
    best, where = np.inf, ""
    for link in model.robot.links:
        if link.name in query["root_links"]:
            continue
        for col in link.collisions:
            geo = col.geometry
            if geo.mesh is not None:
                mesh = trimesh.load(str(urdf.parent / geo.mesh.filename), force="mesh")
                if geo.mesh.scale is not None:
                    mesh.apply_scale(geo.mesh.scale)
                g = bvh(mesh)
            elif geo.box is not None:
                g = fcl.Box(*geo.box.size)
            elif geo.cylinder is not None:
                g = fcl.Cylinder(geo.cylinder.radius, geo.cylinder.length)
            elif geo.sphere is not None:
                g = fcl.Sphere(geo.sphere.radius)
            else:
                continue
            T_lc = np.eye(4) if col.origin is None else np.asarray(col.origin)
            a = placed(g, model.get_transform(link.name) @ T_lc)
            for name, b in scene:
                if fcl.collide(a, b, fcl.CollisionRequest(), fcl.CollisionResult()):
                    return f"triangles intersect: {link.name} x {name}"
                d = fcl.distance(a, b, fcl.DistanceRequest(), fcl.DistanceResult())
                if d < best:
                    best, where = d, f"{link.name} x {name}"
    return f"triangles {best * 1e3:.2f} mm apart ({where})"


def path_checks(P: np.ndarray, query: dict[str, Any]) -> tuple[np.ndarray, str]:
    """The path with its continuous joints unwrapped (a peer may cross +-pi), and whether
    it starts at the start and ends at the goal."""
    cont = np.asarray(query["continuous"], dtype=bool)
    P = P.copy()
    if cont.any():
        P[:, cont] = np.unwrap(P[:, cont], axis=0)
    q0, qg = np.asarray(query["q_start"]), np.asarray(query["q_goal"])

    def gap(a: np.ndarray, b: np.ndarray) -> float:
        d = a - b
        d[cont] = (d[cont] + np.pi) % (2 * np.pi) - np.pi
        return float(np.max(np.abs(d)))

    if gap(P[0], q0) > 1e-6:
        return P, f"does not start at the start ({gap(P[0], q0):.2e} rad)"
    if gap(P[-1], qg) > GOAL_TOL_RAD + 1e-9:
        return P, f"does not end at the goal ({gap(P[-1], qg):.2e} rad)"
    return P, "ends ok"


def one_row(
    arm: str, problem: str, leg: str, planner: str, files: tuple[Path, Path], args: Any
) -> dict[str, Any]:
    toml_file, json_file = files
    query = json.loads(json_file.read_text())
    pdir = args.out / "paths"
    answer = pdir / f"{query['name']}__{planner}.json"
    if answer.is_file() and planner in PEERS and "whole_s" in json.loads(answer.read_text()):
        got = json.loads(answer.read_text())
    elif planner in PEERS:
        got = run_peer(planner, json_file, answer, args)
        write_atomic(answer, json.dumps(got))
    else:
        got = run_plannerlab(toml_file, planner, args)
        write_atomic(answer, json.dumps(got))
    row = {
        "arm": arm,
        "problem": problem,
        "leg": leg,
        "planner": planner,
        "version": got.get("version", ""),
        "solved": bool(got.get("solved")),
        "status": got.get("status", ""),
        "plan_s": got.get("plan_s"),
        "whole_s": got.get("whole_s"),
        "setup_s": got.get("setup_s"),
        "checks": got.get("checks"),
        "start_valid": got.get("start_valid"),
        "goal_valid": got.get("goal_valid"),
        "notes": got.get("notes", []),
    }
    if row["solved"]:
        P, ends = path_checks(np.asarray(got["path"], dtype=float), query)
        seg = np.linalg.norm(np.diff(P, axis=0), axis=1)
        row.update(waypoints=len(P), length_rad=round(float(seg.sum()), 3), ends=ends)
        with tempfile.TemporaryDirectory() as tmp:
            row.update(referee_path(toml_file, P, args.referee_step, Path(tmp)))
        if row["penetrating_states"]:
            Q = interpolate(P, args.referee_step)
            row["triangles"] = triangles_at(query, Q[row["worst_state"]])
    return row


# ---------------------------------------------------------------- the run
def load_rows(path: Path) -> list[dict[str, Any]]:
    if not path.is_file():
        return []
    return [json.loads(s) for s in path.read_text().splitlines() if s.strip()]


def run(args: argparse.Namespace) -> None:
    import pybullet_data
    from mesh_arms_bench import ARMS, make_problems

    for sub in ("problems", "source", "queries", "paths", "urdf"):
        (args.out / sub).mkdir(parents=True, exist_ok=True)
    rows_file = args.out / "rows.jsonl"
    rows = load_rows(rows_file)
    done = {(r["arm"], r["problem"], r["leg"], r["planner"]) for r in rows}
    log(f"start: {len(done)} rows on disk; load average {os.getloadavg()}")
    planners = args.planners.split(",")
    for arm in args.arms.split(","):
        source, rel = ARMS[arm]
        base = args.erd if source == "erd" else Path(pybullet_data.getDataPath())
        if base is None:
            raise SystemExit(f"--erd is needed for {arm}")
        pdir = args.out / "problems"
        files = sorted(pdir.glob(f"{arm}_*.toml"))
        if not files:
            log(f"{arm}: making its problems")
            files = make_problems(arm, base / rel, pdir)
        for f in files:
            problem = f.stem.split("_", 1)[1]
            plan = source_plan(f, args.source_planner, args.source_time_limit, args.out)
            for leg, toml_file, json_file in write_queries(f, plan, args):
                for planner in planners:
                    key = (arm, problem, leg, planner)
                    if key in done:
                        continue
                    log(f"{arm} {problem} {leg} {planner}")
                    row = one_row(arm, problem, leg, planner, (toml_file, json_file), args)
                    row["load"] = round(os.getloadavg()[0], 1)
                    rows.append(row)
                    done.add(key)
                    write_atomic(rows_file, "".join(json.dumps(r) + "\n" for r in rows))
                    log(
                        f"  {row['status'][:80]}; "
                        + (
                            f"{row['plan_s']:.2f} s, {row['referee_states']} states, "
                            f"{row['penetrating_states']} penetrating, "
                            f"min {row['referee_min_mm']} mm"
                            if row["solved"]
                            else "no path"
                        )
                    )
    log(f"end: load average {os.getloadavg()}")


def summary(rows: list[dict[str, Any]]) -> None:
    """Per planner: legs, paths returned, paths the referee refuses, of which the triangles
    intersect, the median of the paths' smallest distances."""
    print(
        "| planner | legs | paths returned | paths penetrating (PyBullet, hulls) "
        "| of which the triangles intersect | median min distance mm | median planning s |"
    )
    print("|" + "---|" * 7)
    for planner in dict.fromkeys(r["planner"] for r in rows):
        mine = [r for r in rows if r["planner"] == planner]
        ok = [r for r in mine if r["solved"]]
        bad = [r for r in ok if r["penetrating_states"]]
        tri = [r for r in bad if "intersect" in r.get("triangles", "")]
        dmin = np.median([r["referee_min_mm"] for r in ok]) if ok else float("nan")
        tmed = np.median([r["plan_s"] for r in ok]) if ok else float("nan")
        print(
            f"| {planner} | {len(mine)} | {len(ok)} | {len(bad)} | {len(tri)} | "
            f"{dmin:.1f} | {tmed:.2f} |"
        )
    print()


def report(args: argparse.Namespace) -> None:
    rows = load_rows(args.out / "rows.jsonl")
    arms = list(dict.fromkeys(r["arm"] for r in rows))
    legs = list(dict.fromkeys(r["leg"] for r in rows))
    order = {p: i for i, p in enumerate(PLANNERS)}
    rows.sort(
        key=lambda r: (
            arms.index(r["arm"]),
            r["problem"],
            legs.index(r["leg"]),
            order.get(r["planner"], 9),
        )
    )
    summary(rows)
    print(
        "| arm | problem | leg | planner | solved | planning s | whole call s | path length rad "
        "| states refereed | penetrating | min distance mm | where |"
    )
    print("|" + "---|" * 12)
    prev = ("", "", "")
    for r in rows:
        key = (r["arm"], r["problem"], r["leg"])
        same = key[0] == prev[0]
        shown = [v if not same or v != p else "" for v, p in zip(key, prev, strict=True)]
        prev = key
        if r["solved"]:
            where = r["referee_where"] if r["penetrating_states"] else ""
            where += f"; {r['triangles']}" if r.get("triangles") else ""
            cells = [
                "yes" if r["ends"] == "ends ok" else r["ends"],
                f"{r['plan_s']:.2f}",
                f"{r['whole_s']:.1f}",
                f"{r['length_rad']:.2f}",
                str(r["referee_states"]),
                f"**{r['penetrating_states']}**" if r["penetrating_states"] else "0",
                f"{r['referee_min_mm']:.1f}",
                where,
            ]
        else:
            plan_s = "" if r.get("plan_s") is None else f"{r['plan_s']:.2f}"
            cells = [f"no: {r['status'][:90]}", plan_s, "", "", "", "", "", ""]
        print("| " + " | ".join([*shown, r["planner"], *cells]) + " |")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--erd", type=Path, default=None, help="example-robot-data's robots/")
    ap.add_argument("--out", type=Path, default=Path("/tmp/peers_mesh"))
    ap.add_argument("--arms", default=DEFAULT_ARMS)
    ap.add_argument("--planners", default=",".join(PLANNERS))
    ap.add_argument("--time-limit", type=float, default=10.0, help="per leg, every planner [s]")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--source-planner", default="native.rrtconnect")
    ap.add_argument("--source-time-limit", type=float, default=30.0)
    ap.add_argument("--referee-step", type=float, default=0.005, help="[rad]")
    ap.add_argument("--mplib", default="/work/peers/mplib/venv/bin/python")
    ap.add_argument("--roboplan", default="/work/peers/roboplan/venv/bin/python")
    ap.add_argument("--report", action="store_true", help="only print the table of the rows")
    args = ap.parse_args()
    args.out = args.out.resolve()
    if args.report:
        report(args)
    else:
        run(args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
