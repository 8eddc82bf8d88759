"""Problems: a robot, a scene, a start state, an ordered list of goals (legs) and budgets.

Problems live in TOML files (``problems/*.toml``); :func:`parse_problem` reads one and
validates every value when the problem is built. Anything wrong raises
:class:`~plannerlab.errors.ProblemError` naming the file, the key and what was expected.
Checks that need the collision checker (a start in collision) are made by
:func:`plannerlab.problem.catalog.load_problem`, which is what users call.

File layout (every key is documented in ``docs/problem-format.md``)::

    [problem]   name, description
    [robot]     type = "armz" | "irb6" | "continuum_chain", then the type's parameters
    [start]     q | q_deg | fill | fill_deg
    [[obstacles]] name, type = "box" | "cylinder" | "sphere", center_m, rpy_deg,
                  size_m | radius_m, length_m
    [[goals]]   name, p_m, n, pos_tol_m, angle_tol_deg     (one per leg, in order)
    [budget]    max_iterations, max_collision_checks, time_limit_s
    [checking]  joint_step       (largest joint step between checked states on an edge)
    [simulation] gravity_mps2, max_track_err_rad
    any other table (e.g. [witness], [continuum]) is kept in ``Problem.extras``.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.errors import ProblemError, UnknownNameError
from plannerlab.problem.goals import GoalRegion
from plannerlab.problem.scene import OBSTACLE_TYPES, Box, Cylinder, Obstacle, Scene, Sphere
from plannerlab.robots import build_robot
from plannerlab.robots.base import Array, Robot, pose_matrix

KNOWN_TABLES = (
    "problem",
    "robot",
    "start",
    "obstacles",
    "goals",
    "budget",
    "checking",
    "simulation",
)


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
        return Budget(**values)

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
        max_track_err_rad: largest joint tracking error [rad] (max over joints and over
            the execution of the wrapped |commanded − actual|) an execution may show and
            still count as executed cleanly.
    """

    gravity_mps2: tuple[float, float, float] = (0.0, 0.0, -9.81)
    max_track_err_rad: float = 0.05


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
        self, name: str, default: Any = ..., *, positive: bool = False, nonnegative: bool = False
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
        return v

    def integer(self, name: str, default: Any = ..., *, minimum: int | None = None) -> int:
        v = self.raw(name, default)
        if isinstance(v, bool) or not isinstance(v, int):
            raise self.fail(name, f"an integer, got {v!r}")
        if minimum is not None and v < minimum:
            raise self.fail(name, f"an integer >= {minimum}, got {v}")
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
        xyz = self.vector(xyz_name, 3)
        rpy_deg = self.vector(rpy_name, 3, default=[0.0, 0.0, 0.0])
        return pose_matrix(xyz, np.deg2rad(rpy_deg))

    def unknown_keys(self, allowed: tuple[str, ...]) -> None:
        extra = sorted(set(self.table) - set(allowed))
        if extra:
            raise self.fail(extra[0], f"is not a known key here; allowed: {', '.join(allowed)}")


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


def _goal(reader: TableReader) -> GoalRegion:
    reader.unknown_keys(("name", "p_m", "n", "pos_tol_m", "angle_tol_deg", "note"))
    p = reader.vector("p_m", 3)
    n = reader.vector("n", 3)
    if float(np.linalg.norm(n)) < 1e-9:
        raise reader.fail("n", f"a non-zero normal vector, got {n.tolist()}")
    return GoalRegion(
        name=reader.string("name"),
        p_world_m=p,
        n_world=n,
        pos_tol_m=reader.number("pos_tol_m", positive=True),
        angle_tol_deg=reader.number("angle_tol_deg", positive=True),
    )


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


def problem_from_dict(data: Mapping[str, Any], source: str) -> Problem:
    """Build a problem from a parsed TOML document; ``source`` names it in errors."""
    top = TableReader(source, "", dict(data))
    meta = TableReader(source, "problem", top.raw("problem"))
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
    goals = tuple(_goal(TableReader(source, f"goals[{i}]", g)) for i, g in enumerate(raw_goals))

    b = TableReader(source, "budget", top.raw("budget", {}))
    b.unknown_keys(("max_iterations", "max_collision_checks", "time_limit_s"))
    budget = Budget(
        max_iterations=b.optional_integer("max_iterations", minimum=1),
        max_collision_checks=b.optional_integer("max_collision_checks", minimum=1),
        time_limit_s=b.optional_number("time_limit_s", positive=True),
    )
    c = TableReader(source, "checking", top.raw("checking", {}))
    c.unknown_keys(("joint_step",))
    joint_step = c.number("joint_step", 0.05, positive=True)

    sim = TableReader(source, "simulation", top.raw("simulation", {}))
    sim.unknown_keys(("gravity_mps2", "max_track_err_rad", "note"))
    simulation = SimSettings(
        gravity_mps2=tuple(float(v) for v in sim.vector("gravity_mps2", 3, (0.0, 0.0, -9.81))),
        max_track_err_rad=sim.number("max_track_err_rad", 0.05, positive=True),
    )

    extras = {k: v for k, v in data.items() if k not in KNOWN_TABLES}
    return Problem(
        name=name,
        robot=robot,
        scene=Scene(tuple(obstacles)),
        q_start=q_start,
        goals=goals,
        budget=budget,
        joint_step=joint_step,
        description=description,
        simulation=simulation,
        source=source,
        extras=extras,
    )


def parse_problem(path: str | Path) -> Problem:
    """Read and validate a problem file (no collision checks; see ``catalog.load_problem``)."""
    path = Path(path)
    source = str(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ProblemError(source, "<file>", "an existing problem file") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ProblemError(source, "<syntax>", f"valid TOML: {exc}") from None
    return problem_from_dict(data, source)
