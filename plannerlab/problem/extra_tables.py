"""The tables kept in ``Problem.extras``, validated: ``[witness]`` (a known collision-free
path or one state per goal, for tests), ``[continuum]`` (collision points and guides for the
continuum planners) and ``[ik_expected]`` (free-form, what tests expect of the IRb-6 IK)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from plannerlab.errors import did_you_mean
from plannerlab.problem.goals import GoalRegion
from plannerlab.problem.reader import TableReader
from plannerlab.robots.base import Robot

#: tables kept in ``Problem.extras`` (validated here, used by tests and some planners)
EXTRA_TABLES = ("witness", "continuum", "ik_expected")


def _witness(reader: TableReader, robot: Robot, goals: tuple[GoalRegion, ...]) -> None:
    reader.unknown_keys(("path_rad", "goal_states_rad", "clearance_floor_m", "note"))
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
    if reader.has("clearance_floor_m"):
        reader.number("clearance_floor_m", nonnegative=True)


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


def read_extras(
    data: Mapping[str, Any],
    source: str,
    robot: Robot,
    goals: tuple[GoalRegion, ...],
    obstacle_names: list[str],
) -> dict[str, Any]:
    """The extra tables of a parsed document, each validated, as they were written (a
    renamed key under its new name)."""
    extras = {k: v for k, v in data.items() if k in EXTRA_TABLES}
    if "witness" in extras:
        witness = TableReader(source, "witness", extras["witness"])
        _witness(witness, robot, goals)
        extras["witness"] = witness.table
    if "continuum" in extras:
        _continuum(TableReader(source, "continuum", extras["continuum"]), obstacle_names)
    if "ik_expected" in extras:
        TableReader(source, "ik_expected", extras["ik_expected"])  # a table, free-form
    return extras
