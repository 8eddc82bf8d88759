"""MotionBenchMaker problems (MoveIt scene + request YAML) as plannerlab problem files.

A MotionBenchMaker problem is a pair of files: ``sceneNNNN.yaml`` (a MoveIt planning scene:
collision objects made of boxes, cylinders and spheres at world poses, an allowed-collision
matrix) and ``requestNNNN.yaml`` (a MoveIt motion plan request: the start state and a goal
given as joint constraints). :func:`problem_toml` turns one pair into the text of a
problem file for a ``type = "urdf"`` robot: the URDF (and SRDF) named by paths relative
to the written file, the start state, every primitive as an obstacle, the allowed pairs of
the scene's matrix as ``allowed_collisions``, and the joint goal as a goal state
(``[[goals]] q``, ``joint_tol_rad`` from the constraints' tolerances). A grasp goal's
object is a declared contact: an obstacle that the end effector's links (the hand and
fingers: :func:`end_effector_links`) touch at the goal state, measured on the robot's
collision model at import (:func:`grasp_contacts`), gets the end effector's links as its
``touch_links``, with a comment saying which touched it (MoveIt's attached object and its
touch links).

MoveIt conventions read here: a box's ``dimensions`` are its full edge lengths (x, y, z), a
cylinder's ``[height, radius]`` along its local z, a sphere's ``[radius]``; orientations are
quaternions ``[x, y, z, w]``; an object may have a ``pose`` of its own, to which its
``primitive_poses`` are relative.

:func:`fetch_vamp` gets one robot's set (7 scenarios × 100 problems), its spherized
URDF and SRDF from the ``vamp-planner`` 0.6.4 source distribution through pip into a
cache folder outside the repository (Apache-2.0; nothing of it is committed but the
Panda URDF, SRDF and licence in ``problems/urdf/panda``). :data:`MBM_ROBOTS` names the
robots: the Panda (7 arm joints), the UR5 with its Robotiq gripper (6 arm joints) and
the Fetch (group ``arm_with_torso``: the torso's prismatic lift and 7 arm joints; its
base, head and gripper fingers are fixed joints of VAMP's spherized URDF, at the values
MotionBenchMaker's start states give them). A request's planning group must be the
robot's: its goal constrains exactly the robot's joints.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import tarfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.robots.base import Array, matrix_to_rpy

#: the source distribution that ships the MotionBenchMaker sets, and what it holds
VAMP_REQUIREMENT = "vamp-planner==0.6.4"
VAMP_SDIST = "vamp_planner-0.6.4.tar.gz"
VAMP_ROOT = "vamp_planner-0.6.4"
#: MotionBenchMaker's scenarios (for each robot a folder ``<name>_<robot>`` of 100 problems)
MBM_SCENARIOS = (
    "bookshelf_small",
    "bookshelf_tall",
    "bookshelf_thin",
    "box",
    "cage",
    "table_pick",
    "table_under_pick",
)
#: ``[checking] joint_step`` of imported problems [rad]: with no margin the edges are
#: checked at it and re-checked at a quarter of it; at 0.05 (plannerlab's default) RRT-Connect
#: paths on table_under_pick failed the re-check (a sphere 1 m out moves 5 cm per step)
DEFAULT_JOINT_STEP_RAD = 0.02
#: the goal tolerance when the request gives none [rad]
DEFAULT_JOINT_TOL_RAD = 1e-3
#: how far outside its URDF limits a start or goal joint value is clipped back into them
#: [rad or m]: the Fetch's roll joints are limited to ±3.14159 and 132 of its goals (12
#: starts) sit at ±π, 2.7e-6 beyond; farther out a state is left as it is (and refused
#: by the problem loader)
LIMIT_SLACK = 1e-5


class MbmFileError(PlannerlabError):
    """A MotionBenchMaker file plannerlab cannot read; names the file and the key."""

    def __init__(self, source: str, key: str, expected: str) -> None:
        super().__init__(f"{source}: [{key}] {expected}")


def default_cache() -> Path:
    """``$PLANNERLAB_CACHE/mbm`` or ``~/.cache/plannerlab/mbm``."""
    base = os.environ.get("PLANNERLAB_CACHE")
    return (Path(base) if base else Path.home() / ".cache" / "plannerlab") / "mbm"


@dataclass(frozen=True)
class MbmRobot:
    """One robot of the MotionBenchMaker sets in the vamp-planner distribution."""

    name: str  #: ``resources/<name>`` of the distribution; its scenario folders end ``_<name>``
    urdf: str  #: the spherized URDF's file name (spheres only: every link a checker can use)
    srdf: str  #: the SRDF's file name (its ``disable_collisions`` pairs)
    tip_link: str  #: the planning group's tip link
    group: str  #: the MoveIt planning group of the requests (``group_name``)


#: the robots :func:`fetch_vamp` knows, by name (tip links: the groups' tips in the SRDFs;
#: the Fetch's ``arm_with_torso`` has no chain there, its arm ends at ``gripper_link``)
MBM_ROBOTS: dict[str, MbmRobot] = {
    "panda": MbmRobot("panda", "panda_spherized.urdf", "panda.srdf", "panda_hand", "panda_arm"),
    "ur5": MbmRobot("ur5", "ur5_spherized.urdf", "ur5.srdf", "ee_link", "manipulator"),
    "fetch": MbmRobot(
        "fetch", "fetch_spherized.urdf", "fetch.srdf", "gripper_link", "arm_with_torso"
    ),
}


@dataclass(frozen=True)
class VampRobot:
    """Where :func:`fetch_vamp` put one robot's set."""

    folder: Path  #: ``resources/<robot>`` of the distribution
    urdf: Path
    srdf: Path
    problems: Path  #: the folder of the ``<scenario>_<robot>`` folders
    licence: Path
    robot: MbmRobot = MBM_ROBOTS["panda"]

    def scenario_folders(self) -> list[Path]:
        """The robot's scenario folders, in :data:`MBM_SCENARIOS` order."""
        return [self.problems / f"{s}_{self.robot.name}" for s in MBM_SCENARIOS]


#: the former name of :class:`VampRobot`
VampPanda = VampRobot


def mbm_robot(name: str) -> MbmRobot:
    """The robot of :data:`MBM_ROBOTS` called ``name`` (a clear error otherwise)."""
    if name not in MBM_ROBOTS:
        raise PlannerlabError(
            f"MotionBenchMaker robot: one of {', '.join(MBM_ROBOTS)}, got {name!r}"
        )
    return MBM_ROBOTS[name]


def fetch_vamp_panda(cache: Path | None = None) -> VampRobot:
    """:func:`fetch_vamp` for the Panda."""
    return fetch_vamp("panda", cache)


def fetch_vamp(robot: str = "panda", cache: Path | None = None) -> VampRobot:
    """Download (``pip download --no-deps vamp-planner==0.6.4``, once) and unpack one
    robot's set (``panda``, ``ur5`` or ``fetch``) into ``cache`` (default
    :func:`default_cache`)."""
    rob = mbm_robot(robot)
    cache = default_cache() if cache is None else Path(cache)
    cache.mkdir(parents=True, exist_ok=True)
    sdist = cache / VAMP_SDIST
    if not sdist.is_file():
        cmd = [sys.executable, "-m", "pip", "download", "--no-deps", VAMP_REQUIREMENT]
        done = subprocess.run([*cmd, "-d", str(cache)], capture_output=True, text=True, check=False)
        if done.returncode != 0 or not sdist.is_file():
            raise PlannerlabError(
                f"{' '.join(cmd)} failed (exit {done.returncode}): {done.stderr.strip()[-400:]}"
            )
    root = cache / VAMP_ROOT
    folder = root / "resources" / rob.name
    if not (folder / rob.urdf).is_file() or not (root / "LICENSE.txt").is_file():
        with tarfile.open(sdist) as tar:
            wanted = [
                m
                for m in tar.getmembers()
                if m.name.startswith(f"{VAMP_ROOT}/resources/{rob.name}/")
                or m.name == f"{VAMP_ROOT}/LICENSE.txt"
            ]
            tar.extractall(cache, members=wanted, filter="data")
    problems = folder / "problems"
    if not (problems / f"{MBM_SCENARIOS[0]}_{rob.name}").is_dir():
        with tarfile.open(folder / "problems.tar.bz2") as tar:
            tar.extractall(folder, filter="data")
    return VampRobot(
        folder=folder,
        urdf=folder / rob.urdf,
        srdf=folder / rob.srdf,
        problems=problems,
        licence=root / "LICENSE.txt",
        robot=rob,
    )


def problem_pairs(folder: Path) -> list[tuple[Path, Path]]:
    """``(sceneNNNN.yaml, requestNNNN.yaml)`` pairs of a scenario folder, by number."""
    folder = Path(folder)
    pairs = []
    for scene in sorted(folder.glob("scene*.yaml")):
        request = folder / scene.name.replace("scene", "request", 1)
        if request.is_file():
            pairs.append((scene, request))
    return pairs


# ---------------------------------------------------------------------- reading
def read_yaml(path: Path) -> Mapping[str, Any]:
    import yaml

    try:
        data = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise MbmFileError(str(path), "<file>", "an existing YAML file") from None
    except yaml.YAMLError as exc:
        raise MbmFileError(str(path), "<syntax>", f"valid YAML: {exc}") from None
    if not isinstance(data, dict):
        raise MbmFileError(str(path), "<file>", f"a YAML mapping, got {type(data).__name__}")
    return data


def _get(data: Any, source: str, key: str) -> Any:
    """``data[a][b]...`` for a dotted key, with an error naming the file and the key."""
    cur = data
    for part in key.split("."):
        if not isinstance(cur, dict) or part not in cur:
            raise MbmFileError(source, key, "is missing")
        cur = cur[part]
    return cur


def _numbers(v: Any, source: str, key: str, n: int | None = None) -> Array:
    ok = isinstance(v, list) and all(
        isinstance(x, int | float) and not isinstance(x, bool) for x in v
    )
    if not ok or (n is not None and len(v) != n):
        raise MbmFileError(source, key, f"a list of {n or 'some'} numbers, got {v!r:.80}")
    a = np.array(v, dtype=float)
    if not np.all(np.isfinite(a)):
        raise MbmFileError(source, key, f"finite numbers, got {v!r:.80}")
    return a


def quaternion_matrix(xyzw: Array) -> Array:
    """Rotation (3, 3) of a quaternion ``[x, y, z, w]`` (normalised here)."""
    x, y, z, w = np.asarray(xyzw, dtype=float) / np.linalg.norm(xyzw)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _pose(p: Any, source: str, key: str) -> Array:
    if not isinstance(p, dict):
        raise MbmFileError(source, key, f"a pose (position, orientation), got {p!r:.80}")
    T = np.eye(4)
    T[:3, 3] = _numbers(p.get("position"), source, f"{key}.position", 3)
    q = _numbers(p.get("orientation", [0, 0, 0, 1]), source, f"{key}.orientation", 4)
    if np.linalg.norm(q) < 1e-9:
        raise MbmFileError(source, f"{key}.orientation", "a non-zero quaternion [x, y, z, w]")
    T[:3, :3] = quaternion_matrix(q)
    return T


@dataclass(frozen=True)
class MbmObstacle:
    """One primitive of a collision object, in plannerlab's terms."""

    name: str
    type: str  #: box, cylinder or sphere
    T_world: Array
    size_m: tuple[float, ...]  #: box: edges; cylinder: (radius, length); sphere: (radius,)


def scene_obstacles(scene: Mapping[str, Any], source: str) -> list[MbmObstacle]:
    """Every primitive of the scene's collision objects (meshes and planes refused)."""
    objects = _get(scene, source, "world.collision_objects")
    if not isinstance(objects, list):
        raise MbmFileError(source, "world.collision_objects", "a list of collision objects")
    out: list[MbmObstacle] = []
    for i, obj in enumerate(objects):
        key = f"world.collision_objects[{i}]"
        if not isinstance(obj, dict):
            raise MbmFileError(source, key, "a collision object (a mapping)")
        oid = str(obj.get("id", f"object{i}"))
        T_obj = _pose(obj["pose"], source, f"{key}.pose") if "pose" in obj else np.eye(4)
        prims = obj.get("primitives", [])
        poses = obj.get("primitive_poses", [])
        if obj.get("meshes") or obj.get("planes"):
            raise MbmFileError(
                source, f"{key}.meshes", "boxes, cylinders and spheres only (no meshes, planes)"
            )
        if not isinstance(prims, list) or not isinstance(poses, list) or len(prims) != len(poses):
            raise MbmFileError(
                source, f"{key}.primitive_poses", "one pose per primitive (two lists, one length)"
            )
        for k, (prim, pose) in enumerate(zip(prims, poses, strict=True)):
            pkey = f"{key}.primitives[{k}]"
            kind = prim.get("type") if isinstance(prim, dict) else None
            dims = _numbers(
                prim.get("dimensions") if isinstance(prim, dict) else None,
                source,
                f"{pkey}.dimensions",
            )
            name = oid if len(prims) == 1 else f"{oid}#{k}"
            T = T_obj @ _pose(pose, source, f"{key}.primitive_poses[{k}]")
            if kind == "box" and len(dims) == 3:
                size: tuple[float, ...] = tuple(float(d) for d in dims)
            elif kind == "cylinder" and len(dims) == 2:
                size = (float(dims[1]), float(dims[0]))  # MoveIt: [height, radius]
            elif kind == "sphere" and len(dims) == 1:
                size = (float(dims[0]),)
            else:
                raise MbmFileError(
                    source,
                    pkey,
                    "a box (3 dimensions), cylinder ([height, radius]) or sphere ([radius]), "
                    f"got {kind!r} with {len(dims)} dimensions",
                )
            if min(size) <= 0:
                raise MbmFileError(source, f"{pkey}.dimensions", "positive dimensions")
            out.append(MbmObstacle(name, str(kind), T, size))
    return out


def allowed_pairs(scene: Mapping[str, Any], source: str, links: Sequence[str]) -> list[list[str]]:
    """The scene's allowed-collision matrix as link pairs (only links of the robot)."""
    acm = scene.get("allowed_collision_matrix")
    if acm is None:
        return []
    names = _get(scene, source, "allowed_collision_matrix.entry_names")
    values = _get(scene, source, "allowed_collision_matrix.entry_values")
    if not (
        isinstance(names, list)
        and isinstance(values, list)
        and len(values) == len(names)
        and all(isinstance(r, list) and len(r) == len(names) for r in values)
    ):
        raise MbmFileError(
            source, "allowed_collision_matrix.entry_values", "a square matrix, one row per name"
        )
    known = set(links)
    out = []
    for i, a in enumerate(names):
        for j in range(i + 1, len(names)):
            b = names[j]
            if (values[i][j] is True or values[j][i] is True) and a in known and b in known:
                out.append([str(a), str(b)])
    return out


def request_states(
    request: Mapping[str, Any], source: str, joint_names: Sequence[str]
) -> tuple[Array, Array, float]:
    """Start state, goal state (in ``joint_names`` order) and goal tolerance [rad]."""
    names = _get(request, source, "start_state.joint_state.name")
    position = _get(request, source, "start_state.joint_state.position")
    if not isinstance(names, list) or not isinstance(position, list):
        raise MbmFileError(source, "start_state.joint_state", "name and position lists")
    pos = _numbers(position, source, "start_state.joint_state.position", len(names))
    by_name = dict(zip(names, pos, strict=True))
    missing = [n for n in joint_names if n not in by_name]
    if missing:
        raise MbmFileError(
            source, "start_state.joint_state.name", f"every joint of the robot; missing {missing}"
        )
    q_start = np.array([by_name[n] for n in joint_names])
    goals = _get(request, source, "goal_constraints")
    if not isinstance(goals, list) or not goals:
        raise MbmFileError(source, "goal_constraints", "a non-empty list")
    if len(goals) > 1:
        raise MbmFileError(source, "goal_constraints", "one goal (a set of joint constraints)")
    cons = goals[0].get("joint_constraints") if isinstance(goals[0], dict) else None
    if not isinstance(cons, list) or not cons:
        raise MbmFileError(
            source, "goal_constraints[0].joint_constraints", "joint constraints (a joint goal)"
        )
    goal: dict[str, float] = {}
    tols = []
    for k, c in enumerate(cons):
        ck = f"goal_constraints[0].joint_constraints[{k}]"
        if not isinstance(c, dict) or "joint_name" not in c or "position" not in c:
            raise MbmFileError(source, ck, "joint_name and position")
        goal[str(c["joint_name"])] = float(_numbers([c["position"]], source, f"{ck}.position")[0])
        for t in ("tolerance_above", "tolerance_below"):
            if t in c:
                tols.append(float(c[t]))
    missing = [n for n in joint_names if n not in goal]
    if missing:
        raise MbmFileError(
            source,
            "goal_constraints[0].joint_constraints",
            f"a constraint on every joint of the robot; missing {missing}",
        )
    extra = [n for n in goal if n not in joint_names]
    if extra:
        raise MbmFileError(
            source,
            "goal_constraints[0].joint_constraints",
            f"constraints on the robot's joints {list(joint_names)} only (the planning "
            f"group must be the robot's); {extra} are not movable joints of its URDF",
        )
    q_goal = np.array([goal[n] for n in joint_names])
    positive = [t for t in tols if t > 0]
    tol = min(positive) if positive else DEFAULT_JOINT_TOL_RAD
    return q_start, q_goal, tol


# ---------------------------------------------------------------------- writing
def end_effector_links(robot: Any) -> list[str]:
    """The URDF links of a URDF chain's end effector: those with collision geometry on the
    last body (moved by the last arm joint) but that joint's own child link (the flange):
    the hand and its fingers (frozen joints ride on the body)."""
    last = int(robot.dof)
    flange = robot._body_links[-1]
    body = np.asarray(robot._cap_body)
    names = robot.link_urdf_names
    return sorted({names[i] for i in np.flatnonzero(body == last)} - {flange})


def grasp_contacts(
    robot: Any, obstacles: Sequence[MbmObstacle], q_goal: Array, margin_m: float
) -> dict[str, list[str]]:
    """Per obstacle that the end effector's links (:func:`end_effector_links`) touch at the
    goal state, measured on the robot's collision model with the file's margin: the links
    in contact (the grasped object, MoveIt's attached object whose ``touch_links`` are the
    end effector's)."""
    from plannerlab.collision.fcl_checker import CollisionChecker
    from plannerlab.problem.scene import Box, Cylinder, Scene, Sphere

    prims: list[Any] = []
    for o in obstacles:
        if o.type == "box":
            prims.append(Box(o.name, o.T_world, np.asarray(o.size_m, dtype=float)))
        elif o.type == "cylinder":
            prims.append(Cylinder(o.name, o.T_world, float(o.size_m[0]), float(o.size_m[1])))
        else:
            prims.append(Sphere(o.name, o.T_world, float(o.size_m[0])))
    ee = set(end_effector_links(robot))
    if not ee or not prims:
        return {}
    checker = CollisionChecker(robot, Scene(tuple(prims)), "fcl", margin_m=float(margin_m))
    urdf_of = dict(zip(robot.link_names, robot.link_urdf_names, strict=True))
    names = set(o.name for o in obstacles)
    out: dict[str, set[str]] = {}
    for a, b in checker.colliding_pairs(np.asarray(q_goal, dtype=float)):
        if b in names and urdf_of.get(a) in ee:
            out.setdefault(b, set()).add(urdf_of[a])
    return {k: sorted(v) for k, v in out.items()}


def _f(x: float) -> str:
    return repr(float(x))


def _vec(v: Any) -> str:
    return "[" + ", ".join(_f(x) for x in np.asarray(v, dtype=float).reshape(-1)) + "]"


def _rel(target: Path, out_dir: Path) -> str:
    return Path(os.path.relpath(Path(target).resolve(), Path(out_dir).resolve())).as_posix()


def problem_toml(
    scene_path: Path,
    request_path: Path,
    *,
    out_path: Path,
    urdf: Path,
    tip_link: str,
    srdf: Path | None = None,
    name: str | None = None,
    safety_margin_m: float = 0.0,
    joint_step_rad: float = DEFAULT_JOINT_STEP_RAD,
) -> str:
    """The text of a plannerlab problem file (to be written at ``out_path``) for one
    MotionBenchMaker problem. The robot is read from ``urdf`` (for its joint order and
    links); paths in the file are relative to ``out_path``'s folder.

    ``safety_margin_m`` is the file's ``[planning] safety_margin_m``: 0 by default, as
    MotionBenchMaker's states are valid with no margin (a margin can make them collide).
    With no margin, edges are checked every ``joint_step_rad`` (``[checking] joint_step``)
    and re-checked at a quarter of it.
    """
    from plannerlab.robots.urdf.model import UrdfChain, UrdfError

    try:
        robot = UrdfChain(Path(urdf), tip_link, srdf_path=srdf)
    except UrdfError as exc:
        raise PlannerlabError(f"{urdf}: {exc}") from None
    scene_src, request_src = str(scene_path), str(request_path)
    scene = read_yaml(scene_path)
    request = read_yaml(request_path)
    obstacles = scene_obstacles(scene, scene_src)
    allowed = allowed_pairs(scene, scene_src, sorted({n.split("#")[0] for n in robot.link_names}))
    q_start, q_goal, tol = request_states(request, request_src, robot.joint_names)
    notes = []
    for label, q in (("start", q_start), ("goal", q_goal)):
        lo, hi = np.asarray(robot.lower), np.asarray(robot.upper)
        near = (q >= lo - LIMIT_SLACK) & (q <= hi + LIMIT_SLACK)
        clipped = np.where(near, np.clip(q, lo, hi), q)
        moved = [robot.joint_names[k] for k in np.flatnonzero(clipped != q)]
        if moved:
            notes.append(
                f"# {label}: {', '.join(moved)} clipped into the URDF's limits "
                f"(at most {np.max(np.abs(clipped - q)):.1e} beyond)"
            )
            q[:] = clipped
    # grasp goals: the objects the hand touches at the goal are declared contacts
    touched = grasp_contacts(robot, obstacles, q_goal, safety_margin_m)
    ee = end_effector_links(robot)
    out_dir = Path(out_path).parent
    stem = name or Path(out_path).stem
    lines = [
        f"# imported from MotionBenchMaker: {Path(scene_path).name}, {Path(request_path).name}",
        "# (plannerlab import mbm)",
        *notes,
        "[problem]",
        f"name = {json.dumps(stem)}",
        f'description = "MotionBenchMaker {Path(scene_path).parent.name}/'
        f'{Path(scene_path).stem}: joint goal, {len(obstacles)} obstacles"',
        "",
        "[robot]",
        'type = "urdf"',
        f'urdf = "{_rel(urdf, out_dir)}"',
        f'tip_link = "{tip_link}"',
    ]
    if srdf is not None:
        lines.append(f'srdf = "{_rel(srdf, out_dir)}"')
    if allowed:
        pairs = ", ".join(f'["{a}", "{b}"]' for a, b in allowed)
        lines.append(f"allowed_collisions = [{pairs}]")
    lines += ["", "[start]", f"q = {_vec(q_start)}", ""]
    lines += ["[planning]", f"safety_margin_m = {_f(safety_margin_m)}", ""]
    lines += ["[checking]", f"joint_step = {_f(joint_step_rad)}", ""]
    for o in obstacles:
        rpy_deg = np.degrees(matrix_to_rpy(o.T_world[:3, :3]))
        lines += [
            "[[obstacles]]",
            f'name = "{o.name}"',
            f'type = "{o.type}"',
            f"center_m = {_vec(o.T_world[:3, 3])}",
            f"rpy_deg = {_vec(rpy_deg)}",
        ]
        if o.type == "box":
            lines.append(f"size_m = {_vec(o.size_m)}")
        elif o.type == "cylinder":
            lines += [f"radius_m = {_f(o.size_m[0])}", f"length_m = {_f(o.size_m[1])}"]
        else:
            lines.append(f"radius_m = {_f(o.size_m[0])}")
        if o.name in touched:
            lines += [
                f"# grasped at the goal: {', '.join(touched[o.name])} touch it (measured on the",
                "# robot's collision model at import); the end effector's links may touch it",
                "touch_links = [" + ", ".join(json.dumps(n) for n in ee) + "]",
            ]
        lines.append("")
    lines += [
        "[[goals]]",
        'name = "goal"',
        f"q = {_vec(q_goal)}",
        f"joint_tol_rad = {_f(tol)}",
        "",
    ]
    if not math.isfinite(safety_margin_m) or safety_margin_m < 0:
        raise PlannerlabError(f"safety_margin_m must be >= 0, got {safety_margin_m}")
    return "\n".join(lines)


__all__ = [
    "MBM_ROBOTS",
    "MBM_SCENARIOS",
    "MbmFileError",
    "MbmObstacle",
    "MbmRobot",
    "VampPanda",
    "VampRobot",
    "allowed_pairs",
    "default_cache",
    "end_effector_links",
    "fetch_vamp",
    "fetch_vamp_panda",
    "grasp_contacts",
    "mbm_robot",
    "problem_pairs",
    "problem_toml",
    "quaternion_matrix",
    "read_yaml",
    "request_states",
    "scene_obstacles",
]
