"""The goal pool of one solve: goal states drawn by IK (or the goal state a clearance
descent finds near the start), filled before planning within the budget. Shared by the
planners that plan towards a pool of goal states (``ompl.*``, ``native.*``)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from plannerlab.planners.context import NearGoal, PlanningContext
from plannerlab.problem.ik import sample_goal_state
from plannerlab.robots.base import Array, wrap_to_pi

__all__ = ["fill_goal_pool", "near_goal_finder", "selection_uses_ik"]


def near_goal_finder(ctx: PlanningContext) -> NearGoal:
    """How ``goal_selection = "near"`` finds a goal state near the start: the caller's
    goal finder (an escape of the clearance descent: its descent, with its settings), or
    else ``gradient.clearance``'s with its default settings."""
    if ctx.near_goal is not None:
        return ctx.near_goal
    from plannerlab.planners.clearance.descent import make as make_clearance

    return make_clearance("gradient.clearance", {}).near_goal_state


def selection_uses_ik(goal_selection: str) -> bool:
    """Whether a ``goal_selection`` may draw goal states by IK (``"ik"``, ``"near_or_ik"``)."""
    return goal_selection != "near"


def fill_goal_pool(
    ctx: PlanningContext,
    settings: Any,
    guard: Any,
    rng: np.random.Generator,
    q0: Array,
    extra: dict[str, Any],
    sampler: Callable[..., Array | None] = sample_goal_state,
) -> tuple[list[Array], str]:
    """The goal pool of one solve (``goal_selection``: IK restarts seeded from ``q0``, the
    goal state found near ``q0``, or that one and IK when it finds none), within the
    budget: the states (wrapped) and why the pool was cut short ("" when it was not).
    Records ``goal_pool``, ``goal_pool_checks`` and (``near_or_ik``) ``goal_near_found``
    in ``extra``.

    ``settings`` gives ``goal_samples``, ``max_goal_attempts`` and ``goal_selection``;
    ``guard`` the checker (``checker``), ``exhausted()``, ``out_of_time()`` and
    ``is_valid(q)`` (refusing once the budget is spent); ``sampler`` the IK goal sampler
    (:func:`~plannerlab.problem.ik.sample_goal_state`), given the robot's compiled IK
    descent when its family has one (:func:`plannerlab.collision.chain_ik.descent_for_robot`)."""
    from plannerlab.collision.chain_ik import descent_for_robot

    s, robot, checker = settings, ctx.robot, guard.checker
    descent = descent_for_robot(robot) if selection_uses_ik(s.goal_selection) else None
    pool: list[Array] = []
    c_pool = checker.checks
    per_slot = max(1, s.max_goal_attempts // max(s.goal_samples, 1))
    pool_cut_short = ""
    selection = s.goal_selection
    near_goal: NearGoal | None = near_goal_finder(ctx) if selection != "ik" else None
    if selection == "near_or_ik":
        assert near_goal is not None
        # the near goal first; when its descent finds none, the IK pool
        q_near = None if guard.exhausted() is not None else near_goal(ctx, q0)
        extra["goal_near_found"] = q_near is not None
        if q_near is not None:
            pool.append(wrap_to_pi(q_near, robot.continuous))
        selection = "near" if pool else "ik"
    for _ in range(s.goal_samples if not pool else 0):
        if guard.exhausted() is not None:
            pool_cut_short = guard.exhausted() or ""
            break
        if selection == "near":
            assert near_goal is not None
            q_goal = near_goal(ctx, q0)
        else:
            q_goal = sampler(
                robot,
                ctx.goal,
                guard,
                rng,
                seeds=[q0],
                attempts=per_slot,
                stop=guard.out_of_time,
                descent=descent,
            )
        if q_goal is not None:
            pool.append(wrap_to_pi(q_goal, robot.continuous))
    extra["goal_pool"] = len(pool)
    extra["goal_pool_checks"] = checker.checks - c_pool
    return pool, pool_cut_short
