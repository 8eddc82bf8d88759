"""The goal: OMPL's goal region on plannerlab's goal distance, and its pool of goal
states (drawn by IK, or the goal state a clearance descent finds near the start), filled
before planning within the budget."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import ompl.base as ob

from plannerlab.planners.context import PlanningContext
from plannerlab.planners.goal_pool import fill_goal_pool as _fill_goal_pool
from plannerlab.planners.goal_pool import near_goal_finder as near_goal_finder
from plannerlab.planners.ompl.guard import Guard
from plannerlab.planners.ompl.settings import GOAL_THRESHOLD, OMPLSettings
from plannerlab.problem.ik import sample_goal_state
from plannerlab.robots.base import Array


def goal_class() -> type:
    """The goal type (created per solve so no OMPL-derived type outlives a solve)."""

    class PoolGoal(ob.GoalSampleableRegion):
        """Goal region with normalised distance and a precomputed IK pool."""

        def __init__(
            self,
            si: Any,
            distance: Callable[[Any], float],
            fill: Callable[[Any, int], None],
            pool_size: int,
        ) -> None:
            super().__init__(si)
            # GoalRegion.distance is exactly 0 inside the region; OMPL's isSatisfied tests
            # distance < threshold (strictly), so "threshold 0" is a tiny positive number.
            self.setThreshold(GOAL_THRESHOLD)
            self._distance = distance
            self._fill = fill
            self._size = pool_size
            self._next = 0

        def distanceGoal(self, state: Any) -> float:  # noqa: N802 - OMPL's name
            return self._distance(state)

        def sampleGoal(self, state: Any) -> None:  # noqa: N802
            self._fill(state, self._next % self._size)
            self._next += 1

        def maxSampleCount(self) -> int:  # noqa: N802
            return self._size

        def couldSample(self) -> bool:  # noqa: N802
            return self._size > 0

    return PoolGoal


def fill_goal_pool(
    ctx: PlanningContext,
    settings: OMPLSettings,
    guard: Guard,
    rng: np.random.Generator,
    q0: Array,
    extra: dict[str, Any],
) -> tuple[list[Array], str]:
    """:func:`plannerlab.planners.goal_pool.fill_goal_pool` with this module's IK sampler
    (``sample_goal_state``, which a bench may replace here)."""
    return _fill_goal_pool(ctx, settings, guard, rng, q0, extra, sampler=sample_goal_state)
