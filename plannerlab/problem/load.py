"""Problems: a robot, a scene, a start state, an ordered list of goals (legs) and budgets.

Problems live in TOML files (``problems/*.toml``); :func:`parse_problem` reads one and
validates every value when the problem is built. Anything wrong raises
:class:`~plannerlab.errors.ProblemError` naming the file, the key and what was expected.
Checks that need the collision checker (a start in collision) are made by
:func:`plannerlab.problem.catalog.load_problem`, which is what users call.

File layout (every key is documented in ``docs/problem-format.md``)::

    [problem]   name, description
    [robot]     type = "armz" | "irb6" | "continuum_chain" | "urdf", then the type's
                parameters
    [start]     q | q_deg | fill | fill_deg
    [[obstacles]] name, type = "box" | "cylinder" | "sphere", center_m, rpy_deg,
                  size_m | radius_m, length_m
    [[goals]]   name, p_m, n, pos_tol_m, angle_tol_deg     (one per leg, in order), or
                name, q | q_deg, joint_tol_rad              (a goal state)
    [budget]    max_iterations, max_collision_checks, time_limit_s
    [checking]  joint_step       (largest joint step between checked states on an edge)
    [planning]  safety_margin_m  (clearance every plan keeps; edge resolution in metres)
    [simulation] gravity_mps2 (default: Arm-Z off, others -9.81 along -z), max_deviation_m,
                max_track_err_rad
    [witness]   path_rad        (a known collision-free path, for tests), goal_states_rad
                (one collision-free state per goal, in leg order), min_clearance_m
    [continuum] collision_points_m, guide_obstacles   (continuum planners)
    [ik_expected] free-form     (what tests expect of the IRb-6 analytic IK)
    Any other table or key is an error ("did you mean ...").
    The last three tables are kept, validated, in ``Problem.extras``.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.errors import ProblemError, UnknownNameError, did_you_mean
from plannerlab.problem.goals import GoalRegion, JointGoal
from plannerlab.problem.scene import OBSTACLE_TYPES, Box, Cylinder, Obstacle, Scene, Sphere
from plannerlab.robots.base import Array, Robot, pose_matrix
from plannerlab.robots.registry import FAMILIES, gravity_off_reason, robot_table
from plannerlab.robots.schema import COMMON_KEYS, Key, RobotTable, TableValueError

KNOWN_TABLES = (
    "problem",
    "robot",
    "start",
    "obstacles",
    "goals",
    "budget",
    "checking",
    "planning",
    "simulation",
)
#: tables kept in ``Problem.extras`` (validated here, used by tests and some planners)
EXTRA_TABLES = ("witness", "continuum", "ik_expected")

#: smallest ``[checking] joint_step`` [rad]: edges are checked every joint_step and
#: re-checked every joint_step / 4, so the cost grows as 1 / joint_step
MIN_JOINT_STEP_RAD = 1e-3
#: default ``[planning] safety_margin_m`` [m]: at least the execution's deviation limit
#: (``[simulation] max_deviation_m``, 0.01 m), so a plan leaves the executor its centimetre
DEFAULT_SAFETY_MARGIN_M = 0.01
#: smallest positive ``[planning] safety_margin_m`` [m]: edges are checked so that no point
#: moves more than the margin between two checked states, so the cost grows as 1 / margin
MIN_SAFETY_MARGIN_M = 1e-3
#: largest ``[planning] safety_margin_m`` [m]
MAX_SAFETY_MARGIN_M = 0.5
#: largest goal angle tolerance [deg]: the angle between two directions is at most 180°
MAX_ANGLE_TOL_DEG = 180.0


@dataclass(frozen=True, eq=False)
class Budget:
    """Limits of one planning call. ``None`` means no limit of that kind.

    Regression tests use iterations or collision checks; time limits are for benchmarks.
    """

    max_iterations: int | None = None
    max_collision_checks: int | None = None
    time_limit_s: float | None = None

    def replace(self, **changes: Any) -> Budget:
        values = {
            "max_iterations": self.max_iterations,
            "max_collision_checks": self.max_collision_checks,
            "time_limit_s": self.time_limit_s,
        }
        values.update({k: v for k, v in changes.items() if v is not None})
        return Budget(**values)  # type: ignore[arg-type]

    def to_dict(self) -> dict[str, Any]:
        return {
            "max_iterations": self.max_iterations,
            "max_collision_checks": self.max_collision_checks,
            "time_limit_s": self.time_limit_s,
        }


@dataclass(frozen=True)
class SimSettings:
    """How the problem is simulated when paths are executed (PyBullet).

    Attributes:
        gravity_mps2: gravity in the world frame [m/s²].
        max_track_err_rad: the joint tracking limit of execution records made before
            ``max_deviation_m`` [rad]; kept for old problem files, it no longer decides
            the verdict (the joint error is reported for information).
        max_deviation_m: largest deviation [m] of any point of the robot's collision
            geometry between the commanded and the simulated state, over the whole
            execution, that an execution may show and still count as executed cleanly.
    """

    gravity_mps2: tuple[float, float, float] = (0.0, 0.0, -9.81)
    max_track_err_rad: float = 0.05
    max_deviation_m: float = 0.01
    #: where the setting came from, in words (shown by ``execute``)
    origin: str = "default"


@dataclass(frozen=True, eq=False)
class Problem:
    """A planning problem. Leg ``i`` goes from the end of leg ``i - 1`` (or the start) to
    ``goals[i]``."""

    name: str
    robot: Robot
    scene: Scene
    q_start: Array
    goals: tuple[GoalRegion, ...]
    budget: Budget = field(default_factory=Budget)
    joint_step: float = 0.05
    #: clearance margin [m] of every planner's validity check and of the final re-check;
    #: also the edge resolution in metres (0: no margin, radian steps only)
    safety_margin_m: float = DEFAULT_SAFETY_MARGIN_M
    description: str = ""
    simulation: SimSettings = field(default_factory=SimSettings)
    source: str = "<memory>"
    extras: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        q = np.array(self.q_start, dtype=float)
        q.setflags(write=False)
        object.__setattr__(self, "q_start", q)

    @property
    def legs(self) -> int:
        return len(self.goals)

    def goal(self, leg: int) -> GoalRegion:
        if not 0 <= leg < len(self.goals):
            raise IndexError(f"{self.name} has legs 0..{len(self.goals) - 1}, not {leg}")
        return self.goals[leg]

    def leg_label(self, leg: int) -> str:
        return self.goals[leg].name

    def resolve_leg(self, leg: int | str) -> int:
        """A leg by index or by its goal's name."""
        if isinstance(leg, int) or (isinstance(leg, str) and leg.isdigit()):
            i = int(leg)
            self.goal(i)
            return i
        names = [g.name for g in self.goals]
        if leg not in names:
            raise UnknownNameError("leg", str(leg), names)
        return names.index(leg)


# ---------------------------------------------------------------------- reading
class TableReader:
    """Typed access to one TOML table with errors that name the file and the key."""

    def __init__(self, source: str, prefix: str, table: Any) -> None:
        if not isinstance(table, dict):
            raise ProblemError(source, prefix, f"a table, got {type(table).__name__}")
        self.source = source
        self.prefix = prefix
        self.table: dict[str, Any] = table

    def key(self, name: str) -> str:
        return f"{self.prefix}.{name}" if self.prefix else name

    def fail(self, name: str, expected: str) -> ProblemError:
        return ProblemError(self.source, self.key(name), expected)

    def has(self, name: str) -> bool:
        return name in self.table

    def raw(self, name: str, default: Any = ...) -> Any:
        if name not in self.table:
            if default is ...:
                raise self.fail(name, "is missing")
            return default
        return self.table[name]

    def string(self, name: str, default: Any = ...) -> str:
        v = self.raw(name, default)
        if not isinstance(v, str):
            raise self.fail(name, f"a string, got {v!r}")
        return v

    def number(
        self,
        name: str,
        default: Any = ...,
        *,
        positive: bool = False,
        nonnegative: bool = False,
        minimum: float | None = None,
        maximum: float | None = None,
        why_maximum: str = "",
    ) -> float:
        v = self.raw(name, default)
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise self.fail(name, f"a number, got {v!r}")
        v = float(v)
        if not math.isfinite(v):
            raise self.fail(name, f"a finite number, got {v}")
        if positive and v <= 0:
            raise self.fail(name, f"a positive number, got {v}")
        if nonnegative and v < 0:
            raise self.fail(name, f"a number >= 0, got {v}")
        if minimum is not None and v < minimum:
            raise self.fail(name, f"a number >= {minimum:g}, got {v:g}")
        if maximum is not None and v > maximum:
            raise self.fail(
                name,
                f"a number <= {maximum:g}, got {v:g}"
                + (f" ({why_maximum})" if why_maximum else ""),
            )
        return v

    def integer(
        self,
        name: str,
        default: Any = ...,
        *,
        minimum: int | None = None,
        maximum: int | None = None,
        why_maximum: str = "",
    ) -> int:
        v = self.raw(name, default)
        if isinstance(v, bool) or not isinstance(v, int):
            raise self.fail(name, f"an integer, got {v!r}")
        if minimum is not None and v < minimum:
            raise self.fail(name, f"an integer >= {minimum}, got {v}")
        if maximum is not None and v > maximum:
            raise self.fail(
                name,
                f"an integer <= {maximum}, got {v}" + (f" ({why_maximum})" if why_maximum else ""),
            )
        return v

    def optional_integer(self, name: str, *, minimum: int | None = None) -> int | None:
        return self.integer(name, minimum=minimum) if self.has(name) else None

    def optional_number(self, name: str, *, positive: bool = False) -> float | None:
        return self.number(name, positive=positive) if self.has(name) else None

    def vector(self, name: str, length: int | None = None, default: Any = ...) -> Array:
        v = self.raw(name, default)
        if not isinstance(v, list | tuple) or any(
            isinstance(x, bool) or not isinstance(x, int | float) for x in v
        ):
            want = f"a list of {length} numbers" if length else "a list of numbers"
            raise self.fail(name, f"{want}, got {v!r}")
        if length is not None and len(v) != length:
            raise self.fail(name, f"a list of {length} numbers, got {len(v)}")
        a = np.array(v, dtype=float)
        if not np.all(np.isfinite(a)):
            raise self.fail(name, f"finite numbers, got {v!r} (NaN or inf)")
        return a

    def pose(self, xyz_name: str, rpy_name: str) -> Array:
        """A pose from a position [m] and roll, pitch, yaw [deg]; either may be left out
        (zero)."""
        xyz = self.vector(xyz_name, 3, default=[0.0, 0.0, 0.0])
        rpy_deg = self.vector(rpy_name, 3, default=[0.0, 0.0, 0.0])
        return pose_matrix(xyz, np.deg2rad(rpy_deg))

    def unknown_keys(self, allowed: tuple[str, ...]) -> None:
        extra = sorted(set(self.table) - set(allowed))
        if extra:
            raise self.fail(
                extra[0],
                f"is not a known key here;{did_you_mean(extra[0], allowed)} "
                f"allowed: {', '.join(allowed)}",
            )


def _obstacle(reader: TableReader) -> Obstacle:
    name = reader.string("name")
    kind = reader.string("type")
    if kind not in OBSTACLE_TYPES:
        raise reader.fail("type", f"one of {', '.join(OBSTACLE_TYPES)}, got {kind!r}")
    T = reader.pose("center_m", "rpy_deg")
    if kind == "box":
        reader.unknown_keys(("name", "type", "center_m", "rpy_deg", "size_m", "note"))
        size = reader.vector("size_m", 3)
        if np.any(size <= 0):
            raise reader.fail("size_m", f"three positive edge lengths, got {size.tolist()}")
        return Box(name, T, size)
    if kind == "cylinder":
        reader.unknown_keys(("name", "type", "center_m", "rpy_deg", "radius_m", "length_m", "note"))
        return Cylinder(
            name,
            T,
            reader.number("radius_m", positive=True),
            reader.number("length_m", positive=True),
        )
    reader.unknown_keys(("name", "type", "center_m", "rpy_deg", "radius_m", "note"))
    return Sphere(name, T, reader.number("radius_m", positive=True))


#: default ``[[goals]] joint_tol_rad`` of a goal state [rad, m for prismatic joints]
DEFAULT_JOINT_TOL_RAD = 1e-3


def _goal(reader: TableReader, robot: Robot) -> GoalRegion:
    if reader.has("q") or reader.has("q_deg"):
        return _joint_goal(reader, robot)
    reader.unknown_keys(("name", "p_m", "n", "pos_tol_m", "angle_tol_deg", "note"))
    p = reader.vector("p_m", 3)
    n = reader.vector("n", 3)
    if float(np.linalg.norm(n)) < 1e-9:
        raise reader.fail("n", f"a non-zero normal vector, got {n.tolist()}")
    name = reader.string("name")
    if not name.strip():
        raise reader.fail("name", "a non-empty name (legs are chosen by it: --legs NAME)")
    angle_tol_deg = reader.number("angle_tol_deg", positive=True)
    if angle_tol_deg > MAX_ANGLE_TOL_DEG:
        raise reader.fail(
            "angle_tol_deg",
            f"an angle in (0, {MAX_ANGLE_TOL_DEG:g}] deg (the angle between two directions is "
            f"at most 180°; 180 accepts any direction), got {angle_tol_deg:g}",
        )
    return GoalRegion(
        name=name,
        p_world_m=p,
        n_world=n,
        pos_tol_m=reader.number("pos_tol_m", positive=True),
        angle_tol_deg=angle_tol_deg,
    )


def _joint_goal(reader: TableReader, robot: Robot) -> JointGoal:
    """A goal state: ``q`` (rad, m for prismatic joints) or ``q_deg``, ``joint_tol_rad``."""
    reader.unknown_keys(("name", "q", "q_deg", "joint_tol_rad", "note"))
    if reader.has("q") and reader.has("q_deg"):
        raise reader.fail("q", "one of q, q_deg (a goal state), not both")
    name = reader.string("name")
    if not name.strip():
        raise reader.fail("name", "a non-empty name (legs are chosen by it: --legs NAME)")
    q = _joint_values(reader, robot, "q" if reader.has("q") else "q_deg")
    tol = reader.number("joint_tol_rad", DEFAULT_JOINT_TOL_RAD, positive=True)
    return JointGoal.at(robot, name, q, tol)


def _joint_values(reader: TableReader, robot: Robot, k: str) -> Array:
    """One value per joint under key ``k`` (``*_deg``: degrees), within the joint limits."""
    q = reader.vector(k)
    if q.shape != (robot.dof,):
        raise reader.fail(k, f"{robot.dof} joint values for this {robot.kind} robot, got {q.size}")
    if k.endswith("_deg"):
        q = np.deg2rad(q)
    lo, hi = robot.lower, robot.upper
    bad = np.flatnonzero(~robot.continuous & ((q < lo - 1e-12) | (q > hi + 1e-12)))
    if bad.size:
        i = int(bad[0])
        raise reader.fail(
            k, f"joint {robot.joint_names[i]} within [{lo[i]:.6g}, {hi[i]:.6g}], got {q[i]:.6g}"
        )
    return q


def _start(reader: TableReader, robot: Robot) -> Array:
    keys = [k for k in ("q", "q_deg", "fill", "fill_deg") if reader.has(k)]
    if len(keys) != 1:
        raise reader.fail(
            "q",
            "exactly one of q, q_deg, fill, fill_deg"
            + (f"; got {', '.join(keys)}" if keys else ""),
        )
    k = keys[0]
    if k.startswith("fill"):
        q = np.full(robot.dof, reader.number(k))
    else:
        q = reader.vector(k)
        if q.shape != (robot.dof,):
            raise reader.fail(
                k, f"{robot.dof} joint values for this {robot.kind} robot, got {q.size}"
            )
    if k.endswith("_deg"):
        q = np.deg2rad(q)
    lo, hi = robot.lower, robot.upper
    bounded = ~robot.continuous
    bad = np.flatnonzero(bounded & ((q < lo - 1e-12) | (q > hi + 1e-12)))
    if bad.size:
        i = int(bad[0])
        raise reader.fail(
            k, f"joint {robot.joint_names[i]} within [{lo[i]:.6g}, {hi[i]:.6g}], got {q[i]:.6g}"
        )
    return q


def _check_tables(top: TableReader) -> None:
    known = KNOWN_TABLES + EXTRA_TABLES
    for k in top.table:
        if k not in known:
            raise top.fail(
                k,
                f"is not a known table;{did_you_mean(k, known)} known tables: {', '.join(known)}",
            )


def _witness(reader: TableReader, robot: Robot, goals: tuple[GoalRegion, ...]) -> None:
    reader.unknown_keys(("path_rad", "goal_states_rad", "min_clearance_m", "note"))
    if not (reader.has("path_rad") or reader.has("goal_states_rad")):
        raise reader.fail(
            "path_rad",
            "a witness path (path_rad) or one witness state per goal (goal_states_rad); "
            "the table has neither",
        )
    if reader.has("path_rad"):
        raw = reader.raw("path_rad")
        if not isinstance(raw, list) or len(raw) < 2:
            raise reader.fail("path_rad", f"a list of at least 2 waypoints, got {raw!r:.80}")
        for i, _ in enumerate(raw):
            row = TableReader(reader.source, reader.prefix, {f"path_rad[{i}]": raw[i]})
            row.vector(f"path_rad[{i}]", robot.dof)
    if reader.has("goal_states_rad"):
        raw = reader.raw("goal_states_rad")
        if not isinstance(raw, list) or len(raw) != len(goals):
            raise reader.fail(
                "goal_states_rad",
                f"a list of {len(goals)} states, one per goal in leg order "
                f"({', '.join(g.name for g in goals)}), got {raw!r:.80}",
            )
        for i, goal in enumerate(goals):
            key = f"goal_states_rad[{i}]"
            q = TableReader(reader.source, reader.prefix, {key: raw[i]}).vector(key, robot.dof)
            pos_err, ang_err = (float(v) for v in goal.errors(robot, q))
            if pos_err > goal.pos_tol_m or ang_err > goal.angle_tol_deg:
                raise reader.fail(
                    key,
                    f"a state inside goal {goal.name!r} (within {goal.pos_tol_m:g} m and "
                    f"{goal.angle_tol_deg:g} deg); its tip is {pos_err:.3g} m and "
                    f"{ang_err:.3g} deg off",
                )
    if reader.has("min_clearance_m"):
        reader.number("min_clearance_m", nonnegative=True)


def _continuum(reader: TableReader, obstacle_names: list[str]) -> None:
    reader.unknown_keys(("collision_points_m", "guide_obstacles", "note"))
    raw = reader.raw("collision_points_m", [])
    if not isinstance(raw, list):
        raise reader.fail("collision_points_m", f"a list of [x, y] points [m], got {raw!r:.80}")
    for i, p in enumerate(raw):
        ok = (
            isinstance(p, list)
            and len(p) in (2, 3)
            and all(
                isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
                for v in p
            )
        )
        if not ok:
            raise reader.fail(
                f"collision_points_m[{i}]",
                f"two or three finite numbers (x, y[, z]) [m], got {p!r}",
            )
    guides = reader.raw("guide_obstacles", [])
    if not isinstance(guides, list) or not all(isinstance(n, str) for n in guides):
        raise reader.fail("guide_obstacles", f"a list of obstacle names, got {guides!r}")
    for n in guides:
        if n not in obstacle_names:
            raise reader.fail(
                "guide_obstacles",
                f"names of obstacles in this problem ({', '.join(obstacle_names) or 'none'}); "
                f"unknown: {n};{did_you_mean(n, obstacle_names)}",
            )


def _simulation(top: TableReader, robot: Robot) -> SimSettings:
    if not top.has("simulation"):
        # a family may default to no gravity: under gravity a 16-m Arm-Z bent sideways
        # needs far more torque than its joints have and collapses in PyBullet, and every
        # bundled Arm-Z problem turns gravity off (see problems/armz_pocket.toml)
        off = gravity_off_reason(robot.kind)
        if off is not None:
            return SimSettings((0.0, 0.0, 0.0), origin=off)
        return SimSettings(origin="gravity -9.81 m/s² along -z: the default")
    sim = TableReader(top.source, "simulation", top.raw("simulation"))
    sim.unknown_keys(("gravity_mps2", "max_track_err_rad", "max_deviation_m", "note"))
    if not sim.has("gravity_mps2"):
        default = _simulation(TableReader(top.source, "", {}), robot)
        g = np.array(default.gravity_mps2)
        origin = default.origin
    else:
        g = sim.vector("gravity_mps2", 3)
        origin = f"gravity {g.tolist()} m/s² from [simulation]"
    return SimSettings(
        gravity_mps2=(float(g[0]), float(g[1]), float(g[2])),
        max_track_err_rad=sim.number("max_track_err_rad", 0.05, positive=True),
        max_deviation_m=sim.number("max_deviation_m", 0.01, positive=True),
        origin=origin,
    )


def _table_value(reader: TableReader, key: Key) -> Any:
    """The value of one declared key (its default when absent), checked as declared."""
    name = key.name
    if key.kind == "integer":
        minimum = None if key.minimum is None else int(key.minimum)
        maximum = None if key.maximum is None else int(key.maximum)
        return reader.integer(
            name, key.default, minimum=minimum, maximum=maximum, why_maximum=key.why_maximum
        )
    if key.kind == "number":
        return reader.number(
            name,
            key.default,
            positive=key.positive,
            minimum=key.minimum,
            maximum=key.maximum,
            why_maximum=key.why_maximum,
        )
    if key.kind == "vector":
        v = reader.vector(name, key.length, default=list(key.default))  # type: ignore[arg-type]
        if key.ordered and v[0] > v[1]:
            unit = f" [{key.unit}]" if key.unit else ""
            raise reader.fail(
                name, f"[lower, upper] with lower <= upper{unit}, got {[float(x) for x in v]}"
            )
        return v
    if key.kind == "pairs":
        raw = reader.raw(name, list(key.default))  # type: ignore[arg-type]
        ok = isinstance(raw, list) and all(
            isinstance(p, list) and len(p) == 2 and all(isinstance(x, str) for x in p) for p in raw
        )
        if not ok:
            raise reader.fail(name, f"a list of [name, name] pairs of strings, got {raw!r:.80}")
        return tuple((a, b) for a, b in raw)
    s = reader.string(name, key.default)
    if key.kind == "path":
        if not s:
            return ""
        folder = Path(reader.source).parent if reader.source != "<memory>" else Path.cwd()
        resolved = (folder / s).resolve()
        if not resolved.is_file():
            raise reader.fail(
                name, f"an existing file, relative to the problem file; {resolved} does not exist"
            )
        return str(resolved)
    if key.choices and s not in key.choices:
        choices = " or ".join(
            f'"{c}"' + (" (the default)" if c == key.default else "") for c in key.choices
        )
        raise reader.fail(name, f"{choices}, got {s!r}")
    return s


def parse_robot_table(reader: TableReader, table: RobotTable) -> dict[str, Any]:
    """Every declared key's checked value (defaults filled in) from a ``[robot]`` table.

    Raises:
        ProblemError: naming the file and ``robot.<key>``: a key the table does not declare
            (with "did you mean"), a value of the wrong kind, out of its limits, or not
            among its choices.
    """
    reader.unknown_keys((COMMON_KEYS[0], *table.names, *COMMON_KEYS[1:]))
    for key in table.keys:
        if key.required and not reader.has(key.name):
            raise reader.fail(key.name, f"is missing ({key.meaning})")
    return {key.name: _table_value(reader, key) for key in table.keys}


def build_robot(reader: TableReader) -> Robot:
    """Build the robot described by a problem file's ``[robot]`` table: its type's declared
    keys are parsed here, then its family's constructor builds it."""
    kind = reader.string("type")
    if kind not in FAMILIES:
        import difflib

        close = difflib.get_close_matches(kind, FAMILIES, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise reader.fail("type", f"one of {', '.join(FAMILIES)}, got {kind!r}{hint}")
    table = robot_table(kind)
    values = parse_robot_table(reader, table)
    try:
        robot: Robot = table.build(values)
    except TableValueError as exc:
        raise reader.fail(exc.key, exc.expected) from None
    return robot


def problem_from_dict(data: Mapping[str, Any], source: str) -> Problem:
    """Build a problem from a parsed TOML document; ``source`` names it in errors."""
    top = TableReader(source, "", dict(data))
    _check_tables(top)
    meta = TableReader(source, "problem", top.raw("problem"))
    meta.unknown_keys(("name", "description", "note"))
    name = meta.string("name")
    description = meta.string("description", "")
    robot_reader = TableReader(source, "robot", top.raw("robot"))
    robot = build_robot(robot_reader)
    q_start = _start(TableReader(source, "start", top.raw("start")), robot)

    raw_obstacles = top.raw("obstacles", [])
    if not isinstance(raw_obstacles, list):
        raise top.fail("obstacles", "an array of tables [[obstacles]]")
    obstacles = [
        _obstacle(TableReader(source, f"obstacles[{i}]", o)) for i, o in enumerate(raw_obstacles)
    ]
    names = [o.name for o in obstacles]
    for i, n in enumerate(names):
        if names.index(n) != i:
            raise ProblemError(source, f"obstacles[{i}].name", f"a unique name; {n!r} is repeated")

    raw_goals = top.raw("goals")
    if not isinstance(raw_goals, list) or not raw_goals:
        raise top.fail("goals", "a non-empty array of tables [[goals]] (one per leg)")
    goals = tuple(
        _goal(TableReader(source, f"goals[{i}]", g), robot) for i, g in enumerate(raw_goals)
    )
    goal_names = [g.name for g in goals]
    for i, n in enumerate(goal_names):
        if goal_names.index(n) != i:
            raise ProblemError(
                source,
                f"goals[{i}].name",
                f"a unique name (legs are chosen by name); {n!r} is also goals"
                f"[{goal_names.index(n)}]",
            )
        if n.isdigit():
            raise ProblemError(
                source,
                f"goals[{i}].name",
                f"a name that is not a number (--legs {n} means leg {n})",
            )

    b = TableReader(source, "budget", top.raw("budget", {}))
    b.unknown_keys(("max_iterations", "max_collision_checks", "time_limit_s", "note"))
    budget = Budget(
        max_iterations=b.optional_integer("max_iterations", minimum=1),
        max_collision_checks=b.optional_integer("max_collision_checks", minimum=1),
        time_limit_s=b.optional_number("time_limit_s", positive=True),
    )
    c = TableReader(source, "checking", top.raw("checking", {}))
    c.unknown_keys(("joint_step", "note"))
    joint_step = c.number("joint_step", 0.05, positive=True)
    if joint_step < MIN_JOINT_STEP_RAD:
        raise c.fail(
            "joint_step",
            f"a step >= {MIN_JOINT_STEP_RAD:g} rad, got {joint_step:g}: every edge is checked "
            f"every joint_step and re-checked every joint_step/4, so one radian of motion "
            f"would cost {4.0 / joint_step:.3g} collision checks",
        )
    if joint_step > math.pi:
        raise c.fail(
            "joint_step", f"a step <= pi rad, got {joint_step:g} (edges would go unchecked)"
        )

    pl = TableReader(source, "planning", top.raw("planning", {}))
    pl.unknown_keys(("safety_margin_m", "note"))
    safety_margin_m = pl.number(
        "safety_margin_m",
        DEFAULT_SAFETY_MARGIN_M,
        nonnegative=True,
        maximum=MAX_SAFETY_MARGIN_M,
        why_maximum="a margin that wide closes every passage",
    )
    if 0.0 < safety_margin_m < MIN_SAFETY_MARGIN_M:
        raise pl.fail(
            "safety_margin_m",
            f"0 (no margin) or a margin >= {MIN_SAFETY_MARGIN_M:g} m, got {safety_margin_m:g}: "
            "edges are checked so that no point moves more than the margin between two "
            "checked states, so a finer margin multiplies the collision checks",
        )

    simulation = _simulation(top, robot)

    extras = {k: v for k, v in data.items() if k in EXTRA_TABLES}
    if "witness" in extras:
        _witness(TableReader(source, "witness", extras["witness"]), robot, goals)
    if "continuum" in extras:
        _continuum(TableReader(source, "continuum", extras["continuum"]), names)
    if "ik_expected" in extras:
        TableReader(source, "ik_expected", extras["ik_expected"])  # a table, free-form
    return Problem(
        name=name,
        robot=robot,
        scene=Scene(tuple(obstacles)),
        q_start=q_start,
        goals=goals,
        budget=budget,
        joint_step=joint_step,
        safety_margin_m=safety_margin_m,
        description=description,
        simulation=simulation,
        source=source,
        extras=extras,
    )


def parse_problem(path: str | Path) -> Problem:
    """Read and validate a problem file (no collision checks; see ``catalog.load_problem``)."""
    path = Path(path)
    source = str(path)
    if path.is_dir():
        raise ProblemError(source, "<file>", "a problem file (.toml), got a directory")
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise ProblemError(source, "<file>", "an existing problem file") from None
    except OSError as exc:
        raise ProblemError(source, "<file>", f"a readable problem file: {exc.strerror}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise ProblemError(
            source,
            "<encoding>",
            f"UTF-8 text (TOML); byte 0x{raw[exc.start]:02x} on line {line} is not UTF-8 "
            "(a binary file, or text saved as Latin-1: save it as UTF-8)",
        ) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ProblemError(source, "<syntax>", f"valid TOML: {exc}") from None
    return problem_from_dict(data, source)
