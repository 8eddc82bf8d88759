"""The clearance descent's escapes that are sub-solves of another planner in the leg's
context (its checks are the leg's): RRT-Connect from the stall (``escape = "rrtconnect"``)
and the detours' last resort, the tip's route (``route_escape``: follow-the-leader from
the stall). The planners come from the registry through the descent's factories
(``escape_planner``, ``route_planner``), so this package imports neither OMPL nor
follow-the-leader.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from typing import Any, Protocol

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.planners.base import Planner
from plannerlab.planners.clearance.settings import ClearanceSettings
from plannerlab.planners.context import PlanningContext, plan_in
from plannerlab.robots.base import Array


class ClearanceDescent(Protocol):
    """What the escapes read of the descent
    (:class:`~plannerlab.planners.clearance.descent.ClearanceDescent`)."""

    name: str
    settings: ClearanceSettings
    escape_planner: Callable[[Mapping[str, Any]], Planner] | None
    route_planner: Callable[[Mapping[str, Any]], Planner] | None

    def near_goal_state(self, ctx: PlanningContext, q: Array) -> Array | None: ...


#: settings of the descent the route's follow-the-leader does not take (it sets its own)
_OWN_ESCAPES = ("escape", "max_escapes", "escape_checks", "route_escape")


def route(
    descent: ClearanceDescent,
    ctx: PlanningContext,
    q_stall: Array,
    used: int,
    rng: np.random.Generator,
) -> tuple[list[Array], int, str]:
    """The detours' last resort: follow-the-leader from the stall (the tip's route
    through free workspace into the goal, tracked with ``descent``'s settings). Returns
    the path from ``q_stall`` (just ``[q_stall]`` when it failed), the iterations and how.

    Why: a stall whose goal lies behind a wall the tip faces (a room entered from
    outside, straight from rest) is left by no retract of the body: each retract's
    descent falls back into the same basin (``armz_deep_a``, ``armz_deep_b``: every
    retract tried, none got in); the way in is the tip's route through the opening."""
    if descent.route_planner is None or not descent.settings.route_escape:
        return [np.array(q_stall)], 0, "no route escape"
    tracker = ctx.tracker
    sub = tracker.remaining(limit_iterations=False)
    if sub is None:
        return [np.array(q_stall)], 0, f"route: {tracker.exhausted() or 'no budget'}"
    b = tracker.budget
    if b.max_iterations is not None:
        sub = sub.replace(max_iterations=max(b.max_iterations - used, 1))
    s = descent.settings
    overrides = {
        f"descent.{f.name}": getattr(s, f.name)
        for f in dataclasses.fields(s)
        if f.name not in _OWN_ESCAPES and getattr(s, f.name) is not None
    }
    leader = descent.route_planner(overrides)
    r = plan_in(leader, ctx.sub(sub, q_stall), rng)
    if r.solved:
        return list(r.path), r.iterations, f"the tip's route ({r.reason})"
    return [np.array(q_stall)], r.iterations, f"the tip's route: {r.status.value}"


def rrtconnect(
    descent: ClearanceDescent, ctx: PlanningContext, q_stall: Array, rng: np.random.Generator
) -> tuple[list[Array], int, str]:
    """RRT-Connect from the stall to a goal state found near it by ``descent``, with its
    settings (:meth:`~ClearanceDescent.near_goal_state`, the sub-solve's goal finder) or,
    when the descent from the stall ends in no collision-free goal state, to
    ``escape_goal_samples`` goal states drawn by IK (OMPL's ``near_or_ik`` goal
    selection), with the checks and time left, at most ``escape_checks`` checks; its
    iterations count in the leg's afterwards (the caller adds them)."""
    if descent.escape_planner is None:
        raise PlannerlabError(
            f"{descent.name}: no escape planner given (make it by name, make_planner)"
        )
    tracker = ctx.tracker
    sub = tracker.remaining(descent.settings.escape_checks, limit_iterations=False)
    if sub is None:
        return [np.array(q_stall)], 0, f"not started: {tracker.exhausted() or 'no budget'}"
    rrt = descent.escape_planner(
        {"goal_selection": "near_or_ik", "goal_samples": descent.settings.escape_goal_samples}
    )
    r = plan_in(rrt, ctx.sub(sub, q_stall, near_goal=descent.near_goal_state), rng)
    if r.solved:
        return list(r.path), r.iterations, "rrtconnect"
    return [np.array(q_stall)], r.iterations, f"rrtconnect: {r.status.value}"


__all__ = ["route", "rrtconnect"]
