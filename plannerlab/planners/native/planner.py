"""The compiled sampling planners behind plannerlab's planner contract:
:class:`NativePlanner` (its settings, checked; the checker and its compiled model built
before the leg's clock; the algorithm's solve, :mod:`~plannerlab.planners.native.solve`)
and :func:`make`, the registry's factory."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.planners.base import PlanResult, with_overrides
from plannerlab.planners.context import LegPlanner, PlanningContext
from plannerlab.planners.native.rrtstar import rrtstar
from plannerlab.planners.native.settings import (
    GOAL_SELECTIONS,
    KPIECESettings,
    NativeSettings,
    RRTConnectSettings,
    RRTstarSettings,
)
from plannerlab.planners.native.solve import NativeSolve
from plannerlab.robots.base import Array


def _check_settings(name: str, s: NativeSettings) -> None:
    if s.goal_selection not in GOAL_SELECTIONS:
        raise PlannerlabError(
            f"{name}: goal_selection must be one of {', '.join(map(repr, GOAL_SELECTIONS))}, "
            f"got {s.goal_selection!r}"
        )
    if not (0.0 <= s.guide_bias <= 1.0):
        raise PlannerlabError(f"{name}: guide_bias must be in [0, 1], got {s.guide_bias!r}")
    for key in ("range_rad", "guide_sigma_rad"):
        v = getattr(s, key)
        if not (math.isfinite(v) and v >= 0.0):
            raise PlannerlabError(f"{name}: {key} must be a finite number >= 0, got {v!r}")
    if not (math.isfinite(s.max_tree_mb) and s.max_tree_mb > 0.0):
        raise PlannerlabError(f"{name}: max_tree_mb must be > 0, got {s.max_tree_mb!r}")
    every = getattr(s, "lazy_every", 1)
    if every < 1:
        raise PlannerlabError(f"{name}: lazy_every must be an integer >= 1, got {every!r}")
    if isinstance(s, KPIECESettings):
        _check_kpiece(name, s)
    if s.goal_samples < 1 or s.max_goal_attempts < 1 or s.shortcut_tries < 0:
        raise PlannerlabError(
            f"{name}: goal_samples and max_goal_attempts must be >= 1 and shortcut_tries "
            f">= 0, got {s.goal_samples}, {s.max_goal_attempts}, {s.shortcut_tries}"
        )


def _check_kpiece(name: str, s: KPIECESettings) -> None:
    def bad(key: str, want: str) -> PlannerlabError:
        return PlannerlabError(f"{name}: {key} must be {want}, got {getattr(s, key)!r}")

    if not 0.0 <= s.goal_bias <= 1.0:
        raise bad("goal_bias", "in [0, 1]")
    for key in ("border_fraction", "failed_score_factor"):
        if not 0.0 < getattr(s, key) <= 1.0:
            raise bad(key, "in (0, 1]")
    if not 0.0 < s.min_valid_fraction < 1.0:
        raise bad("min_valid_fraction", "in (0, 1)")
    if isinstance(s.projection_dims, bool) or s.projection_dims != int(s.projection_dims):
        raise bad("projection_dims", "an integer >= 0")
    if s.projection_dims < 0:
        raise bad("projection_dims", "an integer >= 0")
    if not (math.isfinite(s.cell_size_sd) and s.cell_size_sd > 0.0):
        raise bad("cell_size_sd", "a finite number > 0")
    if not (math.isfinite(s.range_octaves) and 0.0 <= s.range_octaves <= 30.0):
        raise bad("range_octaves", "in [0, 30]")


@dataclass(frozen=True)
class NativePlanner(LegPlanner):
    """A compiled sampling planner with frozen settings (see the module docstring).

    Subclasses that guide the search override :meth:`guide_states`.
    """

    name: str
    algorithm: str
    settings: NativeSettings

    def warm_up(self, problem: Any, leg: int, q_start: Array) -> None:
        """Load (or compile) the kernels of this planner's algorithm before the leg's
        clock starts."""
        from plannerlab.planners.native.warm import warm_up

        warm_up(algorithm=self.algorithm)

    def solve(
        self,
        problem: Any,
        leg: int,
        budget: Any,
        rng: np.random.Generator,
        q_start: Array | None = None,
        stepper: Any = None,
    ) -> PlanResult:
        """:meth:`LegPlanner.solve` with the problem's checker and its compiled model
        built before the leg's clock starts (as the checker is), not in the search's
        time."""
        from plannerlab.collision.fcl_checker import problem_checker

        checker = problem_checker(problem)
        try:
            checker.model  # noqa: B018 - built and kept by the checker
        except ValueError:
            pass  # plan() says why there is none
        ctx = PlanningContext.for_planner(
            self, problem, leg, budget, q_start=q_start, checker=checker, stepper=stepper
        )
        return self.plan(ctx, rng)

    def guide_states(self, ctx: PlanningContext, rng: np.random.Generator) -> Array:
        """The sampler's guide states (k, dof), drawn with probability ``guide_bias``:
        none here (plain sampling). A guided planner returns its own."""
        return np.zeros((0, ctx.robot.dof))

    def require(self, ctx: PlanningContext) -> None:
        """What every native planner needs of its leg: a budget with at least one limit,
        a collision checker and a compiled model of the problem.

        Raises:
            PlannerlabError: naming what is missing.
        """
        b = ctx.tracker.budget
        if b.max_iterations is None and b.max_collision_checks is None and b.time_limit_s is None:
            raise PlannerlabError(
                f"{self.name}: the budget needs at least one limit "
                "(max_iterations, max_collision_checks or time_limit_s)"
            )
        if ctx.checker is None:
            raise PlannerlabError(f"{self.name}: needs a collision checker")
        try:
            ctx.checker.model  # noqa: B018 - built once, raises when it cannot be
        except ValueError as e:
            raise PlannerlabError(f"{self.name}: no compiled model of this problem: {e}") from e

    def plan(self, ctx: PlanningContext, rng: np.random.Generator) -> PlanResult:
        """Plan the leg of ``ctx`` within its budget (at least one limit must be set)."""
        self.require(ctx)
        solve = NativeSolve(self.name, self.settings, ctx, rng, self.guide_states(ctx, rng))
        if self.algorithm == "rrtstar":
            return rrtstar(solve)
        if self.algorithm == "kpiece":
            from plannerlab.planners.native.kpiece_solve import kpiece

            return kpiece(solve)
        return solve.rrtconnect()


#: algorithm -> its settings
SETTINGS: Mapping[str, type[NativeSettings]] = {
    "rrtconnect": RRTConnectSettings,
    "rrtstar": RRTstarSettings,
    "kpiece": KPIECESettings,
}


def make(
    name: str, overrides: Mapping[str, Any] | None = None, *, algorithm: str = "rrtconnect"
) -> NativePlanner:
    """Registry factory: the compiled planner ``algorithm`` with settings overridden by
    name.

    Raises:
        UnknownNameError: unknown setting name (lists the known ones).
        PlannerlabError: unknown algorithm, or a setting out of its range.
    """
    if algorithm not in SETTINGS:
        raise PlannerlabError(f"{name}: no compiled planner {algorithm!r}")
    settings = with_overrides(SETTINGS[algorithm](), dict(overrides or {}), name)
    _check_settings(name, settings)
    return NativePlanner(name=name, algorithm=algorithm, settings=settings)
