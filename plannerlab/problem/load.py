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
                  size_m | radius_m, length_m, touch_links
    [[goals]]   name, p_m, n, pos_tol_m, angle_tol_deg     (one per leg, in order), or
                name, q | q_deg, joint_tol_rad              (a goal state)
    [budget]    max_iterations, max_collision_checks, time_limit_s
    [checking]  joint_step       (largest joint step between checked states on an edge)
    [planning]  safety_margin_m  (clearance every plan keeps; edge resolution in metres)
    [simulation] gravity_mps2 (default: Arm-Z off, others -9.81 along -z), max_deviation_m,
                max_track_err_rad
    [witness]   path_rad        (a known collision-free path, for tests), goal_states_rad
                (one collision-free state per goal, in leg order), clearance_floor_m
    [continuum] collision_points_m, guide_obstacles   (continuum planners)
    [ik_expected] free-form     (what tests expect of the IRb-6 analytic IK)
    Any other table or key is an error ("did you mean ...").
    The last three tables are kept, validated, in ``Problem.extras``.

Each table has its reader beside this module: ``robot_table.py`` (``[robot]``, through the
robot family's declared table), ``scene_table.py`` (``[[obstacles]]``), ``goal_tables.py``
(``[start]``, ``[[goals]]``), ``settings.py`` (``[budget]``, ``[checking]``, ``[planning]``,
``[simulation]``, and the :class:`Budget` and :class:`SimSettings` they make),
``extra_tables.py`` (the extras), all through ``reader.py``'s :class:`TableReader`. This
module puts them together in the file's order of checks: :func:`problem_from_dict`,
:func:`parse_problem`.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.errors import ProblemError, UnknownNameError, did_you_mean
from plannerlab.problem.extra_tables import EXTRA_TABLES, read_extras
from plannerlab.problem.goal_tables import read_goals, read_start
from plannerlab.problem.goals import GoalRegion
from plannerlab.problem.reader import TableReader
from plannerlab.problem.robot_table import build_robot
from plannerlab.problem.scene import Scene
from plannerlab.problem.scene_table import read_scene
from plannerlab.problem.settings import (
    DEFAULT_SAFETY_MARGIN_M,
    Budget,
    SimSettings,
    read_budget,
    read_joint_step,
    read_safety_margin,
    read_simulation,
)
from plannerlab.robots.base import Array, Robot

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


def _check_tables(top: TableReader) -> None:
    known = KNOWN_TABLES + EXTRA_TABLES
    for k in top.table:
        if k not in known:
            raise top.fail(
                k,
                f"is not a known table;{did_you_mean(k, known)} known tables: {', '.join(known)}",
            )


def problem_from_dict(data: Mapping[str, Any], source: str) -> Problem:
    """Build a problem from a parsed TOML document; ``source`` names it in errors."""
    top = TableReader(source, "", dict(data))
    _check_tables(top)
    meta = TableReader(source, "problem", top.raw("problem"))
    meta.unknown_keys(("name", "description", "note"))
    name = meta.string("name")
    description = meta.string("description", "")
    robot = build_robot(TableReader(source, "robot", top.raw("robot")))
    q_start = read_start(TableReader(source, "start", top.raw("start")), robot)
    scene = read_scene(top, robot)
    goals = read_goals(top, robot)
    budget = read_budget(top)
    joint_step = read_joint_step(top)
    safety_margin_m = read_safety_margin(top)
    simulation = read_simulation(top, robot)
    extras = read_extras(data, source, robot, goals, [o.name for o in scene.obstacles])
    return Problem(
        name=name,
        robot=robot,
        scene=scene,
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


#: the loader's names; ``Budget`` is imported from here by the rest of the package
__all__ = ["KNOWN_TABLES", "Budget", "Problem", "SimSettings", "parse_problem", "problem_from_dict"]
