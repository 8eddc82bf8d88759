"""Planners that extend the gradient method against local minima.

``gradient+rrtconnect``
    Gradient descent (the paper's objective); when it stalls in a local minimum,
    RRT-Connect plans from the stalled state into the goal region (goal states from IK).
    If RRT-Connect fails within its slice of the budget, descent resumes from the stalled
    state's neighbourhood and the next stall gets another attempt, up to
    ``max_escapes``. The path is descent, then the RRT-Connect path.
``gradient.multistart``
    Random-restart descent along the path, the remedy TRAC-IK and cuRobo use against
    local minima: at a stall, the arm moves to a random collision-free state near the
    stall (a straight joint-space edge, checked; Gaussian noise growing with every failed
    restart) and descends again. Each restart is part of the path, so the result is an
    executable path, not only a goal state.

Which escape runs is a setting (``escape``: "rrtconnect" or "restart"), not the name.
An escape is counted only when the planner *leaves a stall state*: the escape starts at
the stall (or, with ``retreat_rad`` > 0, at the state the path was cut back to, and the
record says how far that is) and its path moves away from it. Every escape is recorded in
``extra["escapes"]``: where it started (joint-space Euclidean distance from the leg's
start and from the stall [rad]), how far the descent travelled before stalling [rad],
and whether it left the stall. Both planners report ``local_minima`` and ``escapes``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.planners.base import (
    BudgetTracker,
    Planner,
    PlanResult,
    Status,
    with_overrides,
)
from plannerlab.planners.context import LegPlanner, PlanningContext, plan_in
from plannerlab.planners.gradient import GradientPlanner, GradientSettings
from plannerlab.robots.base import Array, joint_difference, wrap_to_pi
from plannerlab.robots.paths import interpolate_edge, path_length


@dataclass(frozen=True)
class HybridSettings:
    """Settings of the hybrid planners.

    Attributes:
        gamma, epsilon, stall_window, stall_min_decrease: the descent's (paper: 0.05, 0.5;
            plannerlab's stall rule).
        gradient: "analytic" (default: the same descent as approx_fprime's, faster) or
            "finite_difference".
        max_escapes: stalls the planner tries to leave before it gives up.
        escape_checks: collision checks one escape attempt may use (RRT-Connect's slice,
            or the restart sampling's).
        rrt_range: RRT-Connect's range (0: OMPL's default).
        restart_noise_rad: first restart's noise (std. dev. per joint) [rad].
        restart_noise_growth: factor on the noise after every failed restart.
        restart_tries: samples per restart before the noise grows.
        retreat_rad: before escaping, the path is cut back along the descent to the last
            state at least this far (largest joint difference) from the stall, or to the
            descent's start, and the escape starts there (0, the default: from the stall
            itself). On the shallow traps the descent stalls within 0.3 rad of the start,
            so a retreat of 0.3 rad escapes from the start: the record says so.
        escape: "rrtconnect" (RRT-Connect from the stall) or "restart" (random restarts
            near the stall).
    """

    gamma: float = 0.05
    epsilon: float = 0.5
    stall_window: int = 60
    stall_min_decrease: float = 1e-3
    gradient: str = "analytic"
    max_escapes: int = 10
    escape_checks: int = 20000
    rrt_range: float = 0.0
    restart_noise_rad: float = 0.3
    restart_noise_growth: float = 1.5
    restart_tries: int = 20
    retreat_rad: float = 0.0
    escape: str = "rrtconnect"

    def descent(self) -> GradientSettings:
        return GradientSettings(
            gamma=self.gamma,
            epsilon=self.epsilon,
            stall_window=self.stall_window,
            stall_min_decrease=self.stall_min_decrease,
            gradient=self.gradient,
        )


class HybridPlanner(LegPlanner):
    """``gradient+rrtconnect`` and ``gradient.multistart`` (see the module docstring).

    Its descents and escapes are sub-solves in the leg's context
    (:meth:`~plannerlab.planners.context.PlanningContext.sub`): one checker, one tracker.
    """

    def __init__(
        self,
        name: str,
        settings: HybridSettings,
        escape_planner: Callable[[Mapping[str, Any]], Planner] | None = None,
    ) -> None:
        self.name = name
        self.settings = settings
        self.escape_planner = escape_planner
        self._descent = GradientPlanner(f"{name}/descent", settings.descent())

    def plan(self, ctx: PlanningContext, rng: np.random.Generator) -> PlanResult:
        s = self.settings
        robot = ctx.robot
        tracker = ctx.tracker  # the sub-solves' iterations charged; their checks its own
        run = ctx.run(self.name, s)
        progress = run.progress
        q = ctx.q_start.copy()
        path: list[Array] = [q]
        trace: list[float] = []
        minima = escapes = 0
        notes: list[str] = []
        noise = s.restart_noise_rad

        def done(status: Status, reason: str) -> PlanResult:
            """The leg's result from the state of the loop."""
            return run.result(
                status,
                reason,
                path,
                iterations=tracker.iterations,
                fk_calls=tracker.fk_calls,
                trace=trace,
                local_minima=minima,
                escapes=escapes,
                extra={"steps": notes, "escapes": escapes_log, "descent_rad": descent_rad},
            )

        escapes_log: list[dict] = []
        descent_rad: list[float] = []

        def dist(a: Array, b: Array) -> float:
            return float(np.linalg.norm(joint_difference(a, b, robot.continuous)))

        if ctx.start_problem is not None:
            return done(Status.INVALID_START, ctx.start_problem)
        while True:
            sub = tracker.remaining()
            if sub is None:
                return done(Status.BUDGET_EXHAUSTED, _used_up(tracker))
            t_sub, c_sub = tracker.elapsed_s, tracker.checks_used
            r = self._descent.plan(ctx.sub(sub, q), rng)
            tracker.charge(r, checks=False)
            progress.extend(r.progress, t_sub, c_sub)
            path.extend(r.path[1:])
            trace.extend(r.trace.tolist())
            descent_rad.append(path_length(r.path, robot.continuous))
            q = r.path[-1]
            notes.append(f"descent: {r.status.value} after {r.iterations} iterations")
            if r.status is Status.SOLVED:
                return done(r.status, f"{r.reason}; {minima} local minima met, {escapes} escaped")
            if r.status is not Status.LOCAL_MINIMUM:
                return done(r.status, r.reason)
            minima += 1
            q_stall = np.array(q)
            if s.retreat_rad > 0:
                q = self._retreat(path, len(r.path) - 1, robot.continuous)
            if minima > s.max_escapes:
                return done(
                    Status.LOCAL_MINIMUM,
                    f"{minima} local minima met, {escapes} escaped; gave up after "
                    f"{s.max_escapes} escape attempts",
                )
            record = {
                "kind": s.escape,
                "stall": minima,
                "start_from_leg_start_rad": dist(q, path[0]),
                "start_from_stall_rad": dist(q, q_stall),
                "descent_before_stall_rad": descent_rad[-1],
                "left_stall": False,
            }
            escapes_log.append(record)
            if s.escape == "rrtconnect":
                t_sub, c_sub = tracker.elapsed_s, tracker.checks_used
                rrt = self._rrt_escape(ctx, rng, q)
                if rrt is None:
                    return done(Status.BUDGET_EXHAUSTED, _used_up(tracker))
                progress.extend(rrt.progress, t_sub, c_sub)  # an escape: a drop to 0
                notes.append(f"rrtconnect from stall {minima}: {rrt.status.value}")
                if rrt.solved:
                    path.extend(rrt.path[1:])
                    left_stall = len(rrt.path) > 1
                    record["left_stall"] = left_stall
                    escapes += int(left_stall)
                    return done(
                        Status.SOLVED,
                        f"descent stalled; RRT-Connect reached the goal region from "
                        f"stall {minima}; {minima} local minima met, {escapes} escaped",
                    )
            # restart near the stall (restart always; rrtconnect after a failed slice)
            q_new = self._restart(ctx, rng, q, noise)
            noise *= s.restart_noise_growth
            if q_new is None:
                notes.append(f"no collision-free restart near stall {minima}")
                continue
            record["left_stall"] = True
            escapes += 1
            path.extend(q_new[1:])
            q = q_new[-1]

    # ------------------------------------------------------------------ escapes
    def _retreat(self, path: list[Array], descent_states: int, continuous: np.ndarray) -> Array:
        """Cut ``path`` back along the descent to the last state at least ``retreat_rad``
        (largest joint difference) from the stall, or to the descent's first state, and
        return it: the escape starts there."""
        s = self.settings
        stall = path[-1]
        first = max(len(path) - 1 - descent_states, 0)
        i = len(path) - 1
        while (
            i > first
            and np.max(np.abs(joint_difference(path[i], stall, continuous))) < s.retreat_rad
        ):
            i -= 1
        del path[i + 1 :]
        return path[-1]

    def _rrt_escape(
        self, ctx: PlanningContext, rng: np.random.Generator, q: Array
    ) -> PlanResult | None:
        """RRT-Connect from q within an escape's slice of the budget (None: none left),
        a sub-solve in the leg's context."""
        if self.escape_planner is None:
            raise PlannerlabError(
                f"{self.name}: no escape planner given (make it by name, make_planner)"
            )
        sub = ctx.tracker.remaining(checks_cap=self.settings.escape_checks)
        if sub is None:
            return None
        overrides = {"range": self.settings.rrt_range} if self.settings.rrt_range > 0 else {}
        r = plan_in(self.escape_planner(overrides), ctx.sub(sub, q), rng)
        ctx.tracker.charge(r, checks=False)
        return r

    def _restart(
        self, ctx: PlanningContext, rng: np.random.Generator, q: Array, noise_rad: float
    ) -> Array | None:
        """A straight, collision-free edge from q to a random state near it: (m, dof),
        checked by the leg's checker."""
        robot, tracker = ctx.robot, ctx.tracker
        for _ in range(self.settings.restart_tries):
            if tracker.remaining() is None:
                break
            q_try = wrap_to_pi(q + rng.normal(0.0, noise_rad, robot.dof), robot.continuous)
            q_try = np.clip(q_try, robot.lower, robot.upper)
            # checked as every planner's edges are: in metres with a margin (the
            # checker's conservative advancement), on the joint_step grid without
            _, bad = ctx.checker.check_edge(q, q_try, ctx.joint_step)
            if bad is None:
                edge = interpolate_edge(q, q_try, ctx.joint_step, robot.continuous)
                return wrap_to_pi(edge, robot.continuous)
        return None


VARIANTS: dict[str, dict[str, object]] = {
    "gradient+rrtconnect": {"escape": "rrtconnect"},
    "gradient.multistart": {"escape": "restart"},
}


def _used_up(tracker: BudgetTracker) -> str:
    return tracker.exhausted() or "budget used up"


def make(
    name: str,
    overrides: dict,
    *,
    escape_planner: Callable[[Mapping[str, Any]], Planner] | None = None,
) -> HybridPlanner:
    """Registry factory for ``gradient+rrtconnect`` and ``gradient.multistart``.

    ``escape_planner(overrides)`` makes the RRT-Connect planner of the escapes (the
    registry passes OMPL's, so this module needs neither the registry nor ``ompl``).
    """
    if name not in VARIANTS:
        raise PlannerlabError(f"{name} is not a hybrid planner ({', '.join(VARIANTS)})")
    settings = with_overrides(HybridSettings(**VARIANTS[name]), overrides, name)  # type: ignore[arg-type]
    if settings.escape not in ("rrtconnect", "restart"):
        raise PlannerlabError(f"escape setting: 'rrtconnect' or 'restart', got {settings.escape!r}")
    if settings.gradient not in ("analytic", "finite_difference"):
        raise PlannerlabError(
            f"gradient setting: 'analytic' or 'finite_difference', got {settings.gradient!r}"
        )
    return HybridPlanner(name, settings, escape_planner)
