"""The legs' states: the ``[start]`` table and the ``[[goals]]`` tables (one per leg, in
order: a tip region, :class:`~plannerlab.problem.goals.GoalRegion`, or a goal state,
:class:`~plannerlab.problem.goals.JointGoal`), joint values within the robot's limits."""

from __future__ import annotations

import numpy as np

from plannerlab.errors import ProblemError
from plannerlab.problem.goals import GoalRegion, JointGoal
from plannerlab.problem.reader import TableReader
from plannerlab.robots.base import Array, Robot

#: largest goal angle tolerance [deg]: the angle between two directions is at most 180°
MAX_ANGLE_TOL_DEG = 180.0
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


def read_start(reader: TableReader, robot: Robot) -> Array:
    """The start state from ``[start]``: exactly one of q, q_deg, fill, fill_deg."""
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


def read_goals(top: TableReader, robot: Robot) -> tuple[GoalRegion, ...]:
    """The goals of the legs in order (``[[goals]]``, at least one), each name unique and
    not a number (legs are chosen by name or by index)."""
    source = top.source
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
    return goals
