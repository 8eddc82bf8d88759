"""The OMPL planner behind plannerlab's planner contract: its settings, the validation
of its budget and settings, OMPL's seed and log bridge around one :class:`~plannerlab.
planners.ompl.driver.Solve`; and :func:`make`, the registry's factory."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import ompl.util as ou

from plannerlab.errors import PlannerlabError
from plannerlab.planners.base import PlanResult, with_overrides
from plannerlab.planners.context import LegPlanner, PlanningContext
from plannerlab.planners.ompl.bridge import LOGGER, SEED_MAX, ompl_logging
from plannerlab.planners.ompl.driver import Solve
from plannerlab.planners.ompl.guard import Guard
from plannerlab.planners.ompl.settings import (
    GOAL_SELECTIONS,
    MOTION_CHECKS,
    SETTINGS_BY_CLASS,
    OMPLSettings,
)
from plannerlab.robots.base import Array


@dataclass(frozen=True)
class OMPLPlanner(LegPlanner):
    """One OMPL geometric planner with frozen settings (see the package docstring)."""

    name: str
    ompl_class: str
    settings: OMPLSettings

    def warm_up(self, problem: Any, leg: int, q_start: Array) -> None:
        """The near goal's descent is compiled: its kernels are loaded (or compiled)
        before the tracker starts, as the checker's core is."""
        if self.settings.goal_selection != "ik":
            from plannerlab.planners.clearance.compiled import warm_up

            warm_up()

    def plan(self, ctx: PlanningContext, rng: np.random.Generator) -> PlanResult:
        """Plan the leg of ``ctx`` within its budget.

        Args:
            ctx: the leg's context (problem, start, goal, checker; the budget's
                iterations / collision checks / time: at least one must be set).
            rng: the trial's generator (IK pool, OMPL seed).

        Returns:
            A :class:`PlanResult`; failures are statuses with reasons.
        """
        budget = ctx.tracker.budget
        if (
            budget.max_iterations is None
            and budget.max_collision_checks is None
            and budget.time_limit_s is None
        ):
            raise PlannerlabError(
                f"{self.name}: the budget needs at least one limit "
                "(max_iterations, max_collision_checks or time_limit_s)"
            )
        if self.settings.motion_check not in MOTION_CHECKS:
            raise PlannerlabError(
                f"{self.name}: motion_check must be one of "
                f"{', '.join(MOTION_CHECKS)}, got "
                f"{self.settings.motion_check!r}"
            )
        if self.settings.goal_selection not in GOAL_SELECTIONS:
            raise PlannerlabError(
                f"{self.name}: goal_selection must be one of "
                f"{', '.join(map(repr, GOAL_SELECTIONS))}, got "
                f"{self.settings.goal_selection!r}"
            )
        ompl_seed = int(rng.integers(1, SEED_MAX))
        with ompl_logging(LOGGER):
            # reseeds OMPL's seed generator, which seeds every generator this solve builds:
            # the solve is determined by this seed whether or not it is the process's first
            # (OMPL then logs that generation has started, and RNG.getSeed() keeps saying
            # the first seed: not the one in effect here, so it is not what is recorded)
            ou.RNG.setSeed(ompl_seed)
            solve = Solve(
                self.name,
                self.ompl_class,
                self.settings,
                ctx,
                Guard(ctx.checker, ctx.tracker),
                rng,
                ompl_seed,
            )
            try:
                result = solve.solve()
            finally:
                solve.close()  # every OMPL object is freed with the solve
        return result

    # ------------------------------------------------------------------ internals


def make(name: str, overrides: Mapping[str, Any] | None = None, *, ompl_class: str) -> OMPLPlanner:
    """Registry factory: the OMPL geometric planner ``ompl_class`` (``"RRTConnect"``, as
    the registry entry ``name`` says), with settings overridden by name.

    Raises:
        UnknownNameError: unknown setting name (lists the known ones).
        PlannerlabError: ``ompl_class`` has no settings here.
    """
    if ompl_class not in SETTINGS_BY_CLASS:
        raise PlannerlabError(f"{name}: OMPL class {ompl_class!r} is not served by this adapter")
    settings = with_overrides(SETTINGS_BY_CLASS[ompl_class](), dict(overrides or {}), name)
    return OMPLPlanner(name=name, ompl_class=ompl_class, settings=settings)
