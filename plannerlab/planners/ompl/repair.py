"""The repair of a found path that the final re-check refuses.

The planner's motions are checked at ``joint_step``, the re-check looks at the states of
the interpolated path at ``joint_step / 4``: a path that OMPL's simplifier pulled taut
against an obstacle passes the first and can graze the obstacle between its checked
states (MotionBenchMaker's Panda problems: 65 of 700 paths, by up to 0.45 mm;
``results/mbm.md``). From here on every motion is checked as the re-check will see it
(OMPL's interpolation of the motion), on a grid twice as fine as the re-check's (a
repaired path is one that runs close to an obstacle):

1. the path as planned, before simplification, is re-checked; if it passes, it is
   simplified again with the strict motion checks (if that one fails the re-check, the
   path as planned is the result);
2. else (``replan``: the planner found an exact solution; not for the roadmap planners,
   nor for the optimizing ones, which would spend all that is left) the planner is
   cleared and solves again, with the strict motion checks, within the budget left, and
   its path is simplified with them.

Whatever comes out is re-checked as the first path was: the re-check stays the judge.
The checks and time of the repair are the leg's.
"""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np
import ompl.base as ob
import ompl.geometric as og

from plannerlab.planners.ompl.guard import Guard
from plannerlab.planners.ompl.settings import (
    CHUNK_STATES,
    ROADMAP,
    SIMPLIFY_MAX_STATES,
    OMPLSettings,
)
from plannerlab.robots.base import Array, wrap_to_pi


class Solve(Protocol):
    """What the repair reads of one solve (:class:`plannerlab.planners.ompl.driver.Solve`,
    which calls it): a protocol, so that this module does not import the driver back."""

    ompl_class: str
    s: OMPLSettings
    guard: Guard
    recheck_step: float
    extra: dict[str, Any]
    si: Any
    space: Any
    pdef: Any
    goal_obj: Any
    planner: Any

    def rows_of(self, ompl_path: Any) -> Array: ...

    def past_time(self) -> bool: ...


def repair(solve: Solve, raw: Any, replan: bool) -> Array | None:
    """A path that passes the re-check, after the simplified one failed it, or None
    (``solve.extra["repair"]`` says how it went); ``raw`` is the OMPL path before
    simplification (see the module docstring)."""
    si, space, guard = solve.si, solve.space, solve.guard
    interpolate, step = solve.s.interpolate, solve.recheck_step
    state_space, between = space.space, space.space.allocState()

    def edge_rows(a: Any, b: Any) -> Array:
        """The motion a -> b as the re-check gets it: OMPL's ``PathGeometric.interpolate``
        of it (``validSegmentCount`` pieces, states at j / n), if set."""
        n = max(int(state_space.validSegmentCount(a, b)), 1) if interpolate else 1
        Q = np.empty((n + 1, space.dof))
        Q[0], Q[n] = space.to_q(a), space.to_q(b)
        for j in range(1, n):
            state_space.interpolate(a, b, j / n, between)
            Q[j] = space.to_q(between)
        return wrap_to_pi(Q, space.robot.continuous)

    class StrictValidator(ob.MotionValidator):
        def checkMotion(self, a: Any, b: Any) -> bool:  # noqa: N802
            return guard.path_valid(edge_rows(a, b), step / 2.0)

    previous, strict = si.getMotionValidator(), StrictValidator(si)
    si.setMotionValidator(strict)
    guard.reserve = 0  # the held path was re-checked: nothing left to hold back
    try:
        return _repair_steps(solve, raw, replan)
    finally:
        si.setMotionValidator(previous)  # no OMPL object outlives the solve


def _repair_steps(solve: Solve, raw: Any, replan: bool) -> Array | None:
    """:func:`repair`'s steps, on the strict motion checks."""
    si, guard, extra = solve.si, solve.guard, solve.extra

    def recheck(ompl_path: Any) -> Array | None:
        """The rows of the path if they pass the re-check within the budget."""
        rows = solve.rows_of(ompl_path)
        left = guard.checks_left()
        if left is not None and guard.checker.grid_states(rows, solve.recheck_step) > left:
            return None
        check = guard.checker.check_path(
            rows, solve.recheck_step, stop=solve.past_time, chunk=CHUNK_STATES
        )
        return rows if check.valid else None

    def simplified(ompl_path: Any) -> Array | None:
        """The path simplified with the strict motion checks, if it passes."""
        if ompl_path.getStateCount() > SIMPLIFY_MAX_STATES or guard.exhausted():
            return None
        short = og.PathGeometric(ompl_path)
        og.PathSimplifier(si, solve.goal_obj).simplify(
            short, ob.PlannerTerminationCondition(guard.poll)
        )
        return recheck(short)

    rows = recheck(raw)
    if rows is not None:
        better = simplified(raw) if solve.s.simplify else None
        extra["repair"] = (
            "the path as planned, simplified again with strict motion checks"
            if better is not None
            else "the path as planned (before simplification)"
        )
        return better if better is not None else rows
    if (
        not replan
        or solve.ompl_class in ROADMAP
        or hasattr(solve.planner, "bestCost")  # an optimizing one would spend all that is left
        or guard.exhausted()
    ):
        extra["repair"] = "the path as planned fails the re-check too"
        return None
    # resume with the budget left, on strict motion checks
    solve.planner.clear()
    solve.pdef.clearSolutionPaths()
    status = solve.planner.solve(ob.PlannerTerminationCondition(guard.poll))
    if status.getStatus() != ob.PlannerStatus.PlannerStatusType.EXACT_SOLUTION:
        extra["repair"] = f"solved again with strict motion checks: {status.asString()}"
        return None
    again = og.PathGeometric(solve.pdef.getSolutionPath())
    rows = simplified(again) if solve.s.simplify else None
    if rows is None:
        rows = recheck(again)
    extra["repair"] = (
        "solved again with strict motion checks"
        if rows is not None
        else "solved again with strict motion checks, and that path fails the re-check"
    )
    return rows
