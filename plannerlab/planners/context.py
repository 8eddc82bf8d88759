"""One planning context per problem and leg: the world a planner plans in.

A :class:`PlanningContext` holds what every planner of one leg needs and used to build
for itself: the problem (robot, scene, resolution), the leg and its goal region, the
collision checker with the problem's clearance margin, the leg's
:class:`~plannerlab.planners.base.BudgetTracker`, the start state and the verdict of its
one collision check. :func:`plannerlab.run.pipeline.solve_legs` builds it once per leg
(with one checker for the whole problem) and hands it to the planner's
:meth:`LegPlanner.plan`; a planner called the old way,
``solve(problem, leg, budget, rng, q_start=None, stepper=None)``, builds it itself
(:meth:`LegPlanner.solve`, the adapter).

Planners that run other planners (the hybrids' descents and RRT-Connect escapes, the
clearance descent's escape, follow-the-leader's detour) give each sub-solve
:meth:`PlanningContext.sub`: the same checker (no second one is built), a tracker that is
a child of the leg's (its own slice of the budget; its checks are the leg's, seen through
the shared checker, and whatever it is charged is charged to the leg's too), and a start
state that is not checked again (it is a state of the caller's path, checked there). An
escape that looks for a goal state near its start uses its caller's goal finder
(:attr:`PlanningContext.near_goal`), with the caller's settings.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from plannerlab.planners.base import BudgetTracker, LegRun, PlanResult, Stepper, start_collision
from plannerlab.robots.base import Array

__all__ = ["LegPlanner", "NearGoal", "PlanningContext", "plan_in"]

#: a goal finder: a collision-free state in the context's goal region near a state, or None
NearGoal = Callable[["PlanningContext", Array], "Array | None"]


@dataclass(frozen=True)
class PlanningContext:
    """The world of one leg's solve (see the module docstring).

    Attributes:
        problem: the problem (robot, scene, goals, ``joint_step``, ``safety_margin_m``).
        leg: the leg's index; ``goal`` its goal region.
        checker: the problem's collision checker, with its clearance margin
            (:func:`~plannerlab.collision.fcl_checker.problem_checker`); every check
            counts. (A contact-permitting planner's leg may have none.)
        tracker: the leg's budget tracker (a sub-solve's: a child of the caller's); it
            counts ``checker``'s checks, but for a contact-permitting planner's leg.
        q_start: (dof,) the state the leg starts from.
        start_checked: whether :attr:`start_problem` is the verdict of a check (False: a
            contact-permitting planner's leg, whose start is not checked for collision).
        start_problem: why the leg cannot start at ``q_start`` (its colliding pairs in
            words), or None: the one start-state check, made when the context was built
            and counted by the tracker. A sub-solve's context says None: its start is a
            state of the caller's path.
        stepper: the simulator of closed-loop planners (None: kinematic).
        near_goal: the caller's goal finder, for an escape that selects a goal state near
            its start (None: the escape's own default).
    """

    problem: Any
    leg: int
    goal: Any
    checker: Any
    tracker: BudgetTracker
    q_start: Array
    start_checked: bool
    start_problem: str | None
    stepper: Stepper | None = None
    near_goal: NearGoal | None = None

    @classmethod
    def build(
        cls,
        problem: Any,
        leg: int,
        budget: Any,
        *,
        q_start: Array | None = None,
        checker: Any | None = None,
        stepper: Stepper | None = None,
        warm_up: Callable[[Any, int, Array], None] | None = None,
        contact: bool = False,
    ) -> PlanningContext:
        """The context of leg ``leg``: the checker (``checker``, or the problem's, built
        here), then ``warm_up(problem, leg, q_start)`` (a planner's one-off costs of the
        process: its compiled kernels loaded), then the tracker, whose clock
        (``budget.clock``, default the wall's) starts now, and the start-state check (one
        collision check when the start is free), counted by it. A planner's set-up for
        the problem (a clearance field, a grid, a goal pool) is built in ``plan``, in the
        leg's time, and stops when that is spent.

        Args:
            problem: the problem; ``leg`` the leg's index.
            budget: the leg's limits.
            q_start: (dof,) start (default: the problem's start).
            checker: the problem's checker when the caller has one (one per problem).
            stepper: the simulator of a closed-loop planner.
            warm_up: a planner's one-off preparation of the process (compiled kernels
                loaded), kept outside the limits.
            contact: the leg of a contact-permitting planner (its paths touch obstacles
                by design): its start is not checked for collision, and its tracker
                counts only the checks the planner charges (its contact classification),
                so its result measures no planned clearance.
        """
        q0 = np.array(problem.q_start if q_start is None else q_start, dtype=float)
        if checker is None and not contact:  # a contact leg checks nothing with it
            from plannerlab.collision.fcl_checker import problem_checker

            checker = problem_checker(problem)
        if warm_up is not None:
            warm_up(problem, leg, q0)
        tracker = BudgetTracker(budget, None if contact else checker)
        return cls(
            problem=problem,
            leg=leg,
            goal=problem.goal(leg),
            checker=checker,
            tracker=tracker,
            q_start=q0,
            start_checked=not contact,
            start_problem=None if contact else start_collision(checker, q0),
            stepper=stepper,
        )

    @classmethod
    def for_planner(
        cls,
        planner: Any,
        problem: Any,
        leg: int,
        budget: Any,
        *,
        q_start: Array | None = None,
        checker: Any | None = None,
        stepper: Stepper | None = None,
    ) -> PlanningContext:
        """:meth:`build` for ``planner``: its ``warm_up`` if it has one, and a contact
        leg for a contact-permitting planner (``allows_contact``)."""
        return cls.build(
            problem,
            leg,
            budget,
            q_start=q_start,
            checker=checker,
            stepper=stepper,
            warm_up=getattr(planner, "warm_up", None),
            contact=bool(getattr(planner, "allows_contact", False)),
        )

    # ------------------------------------------------------------------ the problem's parts
    @property
    def robot(self) -> Any:
        return self.problem.robot

    @property
    def scene(self) -> Any:
        return self.problem.scene

    @property
    def joint_step(self) -> float:
        """The problem's edge resolution [rad]."""
        return float(self.problem.joint_step)

    @property
    def margin_m(self) -> float:
        """The checker's clearance margin [m]."""
        return float(getattr(self.checker, "margin_m", 0.0))

    # ------------------------------------------------------------------ sub-solves, results
    def sub(
        self, budget: Any, q_start: Array, *, near_goal: NearGoal | None = None
    ) -> PlanningContext:
        """The context of a sub-solve from ``q_start`` (a state of the caller's path,
        not checked again) within ``budget`` (a slice of what the leg has left,
        :meth:`BudgetTracker.remaining`): the same problem, leg, goal, checker and
        stepper, a child of the leg's tracker, and ``near_goal``, the caller's goal
        finder, if it gives one."""
        return dataclasses.replace(
            self,
            tracker=self.tracker.child(budget),
            q_start=np.array(q_start, dtype=float),
            start_checked=False,
            start_problem=None,
            near_goal=near_goal,
        )

    def run(self, planner: str, settings: Any) -> LegRun:
        """The :class:`~plannerlab.planners.base.LegRun` of ``planner`` on this leg: the
        one way its result is built."""
        return LegRun(planner, settings, self.problem, self.leg, self.tracker)


class LegPlanner:
    """Base of plannerlab's planners: :meth:`plan` takes the leg's context;
    :meth:`solve` is the planner contract's call, which builds the context
    (:meth:`PlanningContext.for_planner`) and plans in it.

    A subclass sets ``name`` and ``settings`` and implements :meth:`plan`; it may
    implement :meth:`warm_up` (one-off costs of the process, compiled kernels loaded,
    kept outside the time limit; set-up for the problem belongs in :meth:`plan`, inside
    it: ``ctx.tracker.time_up`` is its poll) and set
    ``allows_contact`` (a planner whose paths touch obstacles by design: no start check).
    """

    name: str
    settings: Any
    #: the planner's paths touch obstacles by design (the contact-permitting chord_arc)
    allows_contact: ClassVar[bool] = False

    def warm_up(self, problem: Any, leg: int, q_start: Array) -> None:
        """Prepare what is built once (before the leg's tracker starts): nothing here."""

    def plan(self, ctx: PlanningContext, rng: np.random.Generator) -> PlanResult:
        """Plan the leg of ``ctx`` (its start, goal, checker and budget)."""
        raise NotImplementedError

    def solve(
        self,
        problem: Any,
        leg: int,
        budget: Any,
        rng: np.random.Generator,
        q_start: Array | None = None,
        stepper: Stepper | None = None,
    ) -> PlanResult:
        """Plan leg ``leg`` of ``problem`` from ``q_start`` (default: the problem's start)
        within ``budget``: the planner contract's call (:class:`~plannerlab.planners.base.
        Planner`), in a context built for it."""
        ctx = PlanningContext.for_planner(
            self, problem, leg, budget, q_start=q_start, stepper=stepper
        )
        return self.plan(ctx, rng)


def plan_in(planner: Any, ctx: PlanningContext, rng: np.random.Generator) -> PlanResult:
    """``planner``'s solve in ``ctx``: a sub-solve (an escape, a detour) in its caller's
    context. The planner must plan in a given context (a :class:`LegPlanner`)."""
    plan = getattr(planner, "plan", None)
    if plan is None:
        from plannerlab.errors import PlannerlabError

        raise PlannerlabError(
            f"{planner.name}: a sub-solve plans in its caller's context: the planner "
            "needs plan(ctx, rng) (plannerlab.planners.context.LegPlanner)"
        )
    result: PlanResult = plan(ctx, rng)
    return result
