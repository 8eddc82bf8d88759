"""The gradient method with a clearance term: a descent that slides along walls.

The paper's objective ``f(S) = r1 |p − p_d| + r2 (1 − n·n_d)²`` (eq. 3) replaces the
collision penalty A(S), which is flat everywhere but at contact, by a smooth clearance
term (:mod:`plannerlab.planners.clearance`)::

    F(S) = f(S) + w · Σ_pairs (m − d)² / m        over link pairs closer than m

so a link that nears a wall or another link is pushed away before it touches, and the
descent slides along the wall instead of stopping at it. Every accepted state is checked
by the collision checker (steps are at most ``joint_step`` per joint, so the path is
checked edge by edge at the problem's resolution).

Two step rules, both on F:

``direction = "gradient"``
    Steepest descent, the paper's rule, with the step scaled so that its largest joint
    change is the trust radius (the paper's γ∇f on a 16-m arm moves the base by radians).
``direction = "gauss_newton"``
    F written as a sum of squares (the tip residuals in units of the goal's tolerances,
    one residual ``√(w/m)(m − d)`` per close pair) and a damped Gauss-Newton step on it:
    the same minimum, a step that does not let the base joints' long lever arms dominate.

The trust radius grows by 1.5 after an accepted step (up to ``joint_step``) and halves
after a rejected one (F did not decrease or the state collides). A **stall** is declared
when the best ``f`` has not decreased by ``stall_min_decrease`` in ``stall_window``
iterations, or the trust radius falls below ``min_step_rad``: status ``local_minimum``
with ``extra["q_stall"]`` and ``extra["descent_rad"]`` (joint-space distance travelled).

Towards a goal state (:class:`~plannerlab.problem.goals.JointGoal`) the tip terms give
way to the joint residual ``e = (q_goal − q) / tol_rad`` (continuous joints wrapped; its
Jacobian ``I / tol_rad``): the Gauss-Newton step is taken on it beside the clearance
residuals, and a step is accepted when it lowers the sum of squares that step models,
``F = |e|² + w · cost`` (``direction = "gradient"``: the step is −∇F). Accepting on
``r1 |q − q_goal| + w · cost`` instead, whose balance with the clearance differs from the
step's by ``|q − q_goal| / tol_rad²``, stalled the descent where the step closed on a wall
(measured, ``gradient.clearance+detour``: 14 of the 56 legs of room variants v00-v07
towards their witness states solved, against 40 of 56). ``f``, which the
stall test and the trace follow, is ``r1 |q − q_goal|`` [rad]. "Inside" and "deep" are the
largest joint difference against ``tol_rad`` and ``goal_depth · tol_rad``, and there is
no approach point (the goal state says how the arm comes in). Sub-goals of the escapes
stay tip targets.

Escapes from a stall (``escape`` setting): ``detour`` (sub-goals near the stall: the tip
drawn back along its own body, ``retract_step``, ``2 retract_step``, … modules, each
followed by the leg's descent; deterministic), ``rrtconnect`` (RRT-Connect from the stall
to a goal state found near it, or, when the descent near the stall finds none, to goal
states drawn by IK) and ``random_detour``, the detour with its sub-goals drawn
from the planner's generator: each retract goes back a random ``1 … 2 retract_step``
modules further than the last and aims at a point drawn uniformly in a ball of
``retract_jitter_m`` round the body's face there; a detour that finds no way is drawn
again from the same stall, up to ``max_escapes`` draws. Its seeds are different runs, so
a success rate over seeds says how often such an escape works (the ``detour``'s seeds are
one run repeated).

The settings are in :mod:`~plannerlab.planners.clearance.settings`, the step in numpy in
:mod:`~plannerlab.planners.clearance.step` (a base of :class:`ClearanceDescent`), the field
and step on either engine in :mod:`~plannerlab.planners.clearance.models`; this module holds
the descent and its escapes (the sub-solves of other planners in
:mod:`~plannerlab.planners.clearance.escapes`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from plannerlab.collision.fcl_checker import CollisionChecker
from plannerlab.errors import PlannerlabError
from plannerlab.planners.base import (
    Planner,
    PlanResult,
    Status,
    with_overrides,
)
from plannerlab.planners.clearance.escapes import route, rrtconnect
from plannerlab.planners.clearance.field import ClearanceField, SetupStopped
from plannerlab.planners.clearance.legpath import LegPath
from plannerlab.planners.clearance.models import CompiledStep, Model, NumpyModel
from plannerlab.planners.clearance.settings import ClearanceSettings, robot_size
from plannerlab.planners.clearance.slide import Slide, deep_inside, sight_clearance_m, slide_out
from plannerlab.planners.clearance.step import DescentStep
from plannerlab.planners.context import LegPlanner, PlanningContext
from plannerlab.problem.goals import GoalRegion, JointGoal
from plannerlab.robots.base import Array, joint_difference, wrap_to_pi
from plannerlab.robots.paths import path_length


class ClearanceDescent(DescentStep, LegPlanner):
    """One descent of F from a start state (see the module docstring)."""

    def __init__(
        self,
        name: str,
        settings: ClearanceSettings,
        escape_planner: Callable[[Mapping[str, Any]], Planner] | None = None,
        route_planner: Callable[[Mapping[str, Any]], Planner] | None = None,
    ) -> None:
        self.name = name
        self.settings = settings
        self.escape_planner = escape_planner
        #: makes follow-the-leader (overrides -> planner) for the detours' route escape
        self.route_planner = route_planner
        #: (problem, its model): the field of the last problem solved (see :meth:`model`)
        self._model_cache: tuple[Any, Model] | None = None
        #: (robot, this descent with its distances derived for it) (see :meth:`for_robot`)
        self._resolved: tuple[Any, ClearanceDescent] | None = None

    def for_robot(self, robot: Any) -> ClearanceDescent:
        """This descent with its derived distance settings (None: ``influence_m``,
        ``clearance_floor_m``, ``approach_m``, …) set for ``robot``
        (:meth:`ClearanceSettings.for_robot`); itself when none is left to derive. Every
        entry point plans with it, so a solve's result records the values used."""
        if self.settings.resolved:
            return self
        cached = self._resolved
        if cached is not None and cached[0] is robot:
            return cached[1]
        descent = ClearanceDescent(
            self.name, self.settings.for_robot(robot), self.escape_planner, self.route_planner
        )
        self._resolved = (robot, descent)
        return descent

    # ------------------------------------------------------------------ pieces
    def _settle(
        self,
        robot,
        goal,
        model: Model,
        q: Array,
        checker: CollisionChecker,
        max_step: float,
        path: list[Array],
    ) -> int:
        """In the goal region: descend the clearance term alone, staying within
        ``settle_fraction`` of the tolerances, so the arm does not end a few centimetres
        from a wall when the region leaves room (a tracking arm overshoots a little).
        Appends the accepted states to ``path``; returns the iterations used."""
        s = self.settings
        c = model.point(goal, q)
        radius = max_step
        used = 0
        for used in range(1, s.settle_iterations + 1):  # noqa: B007
            g = c.gradient
            big = float(np.max(np.abs(g), initial=0.0))
            if c.cost <= 0.0 or big < 1e-12 or radius < s.min_step_rad:
                break
            q_new = wrap_to_pi(q - g * (radius / big), robot.continuous)
            c_new = model.point(goal, q_new)
            if (
                c_new.cost < c.cost
                and _within(goal, c_new, s.settle_fraction)
                and checker.is_valid(q_new)
            ):
                q, c = q_new, c_new
                path.append(q.copy())
                radius = min(radius * 1.5, max_step)
            else:
                radius *= 0.5
        return used

    def backend_for(self, robot: Any) -> str:
        """The engine the field runs on for ``robot``: "compiled" (the ``backend``
        setting's default) on an Arm-Z, else "numpy"."""
        if self.settings.backend == "compiled" and getattr(robot, "kind", "") == "armz":
            return "compiled"
        return "numpy"

    def model(self, problem, stop: Callable[[], bool] | None = None, checker: Any = None) -> Model:
        """The field and step of ``problem`` on the ``backend`` setting's engine (built
        once per problem and kept: building the field's pair lists takes milliseconds,
        and is bounded, :data:`~plannerlab.planners.clearance.MAX_SPHERES`). It is built
        in the first solve's time: ``stop()`` (the leg's time limit) is asked while it is
        built, and True raises :class:`~plannerlab.planners.clearance.SetupStopped`.
        The compiled engine's spheres ride on the ``checker``'s compiled robot–scene
        model when it has one (else on the robot's chain packed alone: the same
        kinematics)."""
        resolved = self.for_robot(problem.robot)
        if resolved is not self:
            return resolved.model(problem, stop, checker)
        cached = self._model_cache
        if cached is not None and cached[0] is problem:
            return cached[1]
        field = ClearanceField(problem.robot, problem.scene, self.settings.influence_m, stop=stop)
        model: Model
        if self.backend_for(problem.robot) == "compiled":
            model = CompiledStep(self, field)
        else:
            model = NumpyModel(self, field)
        self._model_cache = (problem, model)
        return model

    # ------------------------------------------------------------------ solve
    def descend(
        self,
        ctx: PlanningContext,
        q_start: Array,
        goal=None,
        iterations_before: int = 0,
        *,
        checked: bool = True,
    ) -> tuple[Status, str, list[Array], list[float], int]:
        """Descend from q_start in the leg's context; returns status, reason, path, f per
        iteration, iterations.

        ``goal`` overrides the leg's goal region (sub-goals of escapes). ``checked`` False:
        the states are not checked (goal selection near q_start). ``iterations_before``:
        iterations the leg has already used (the budget is the leg's, ``ctx.tracker``).
        """
        resolved = self.for_robot(ctx.robot)
        if resolved is not self:
            return resolved.descend(ctx, q_start, goal, iterations_before, checked=checked)
        s = self.settings
        problem, robot, tracker = ctx.problem, ctx.robot, ctx.tracker
        checker = ctx.checker if checked else None
        goal = goal if goal is not None else ctx.goal
        model = self.model(problem, tracker.time_up, ctx.checker)
        max_step = s.max_step_rad if s.max_step_rad > 0 else problem.joint_step / 2
        q = np.array(q_start, dtype=float)
        path = [q.copy()]
        here = model.point(goal, q)
        f_now = here.f
        trace = [f_now]
        best, best_iter = f_now, 0
        radius = max_step
        iteration = 0
        inside_since = 0
        d_now = here.distances_m
        direction, F_now = here.direction, here.F
        held = False
        while True:
            inside = _within(goal, here, 1.0)
            deep = _within(goal, here, s.goal_depth)
            stalled = iteration - best_iter >= s.stall_window or radius < s.min_step_rad
            # inside the region the descent goes on towards goal_depth of the tolerances
            # (an executed path then ends inside too), as long as it makes progress
            if deep or (inside and (stalled or iteration - inside_since >= s.deepen_iterations)):
                if checker is not None and s.settle_iterations > 0:
                    iteration += self._settle(robot, goal, model, q, checker, max_step, path)
                return (
                    Status.SOLVED,
                    f"in the goal region after {iteration} iterations",
                    path,
                    trace,
                    iteration,
                )
            if not inside:
                inside_since = iteration + 1
            if stalled:
                why = (
                    f"best f = {best:.4g} has not improved by {s.stall_min_decrease} in "
                    f"{s.stall_window} iterations"
                    if radius >= s.min_step_rad
                    else f"no step of {s.min_step_rad} rad lowers F"
                )
                return (
                    Status.LOCAL_MINIMUM,
                    f"stalled at iteration {iteration}: {why}",
                    path,
                    trace,
                    iteration,
                )
            exhausted = tracker.exhausted(iterations_before + iteration)
            left = tracker.checks_left()
            if exhausted is None and left is not None and left < 1:
                exhausted = (
                    f"collision-check budget of {tracker.budget.max_collision_checks} used up"
                )
            if exhausted:
                return Status.BUDGET_EXHAUSTED, exhausted, path, trace, iteration
            iteration += 1
            big = float(np.max(np.abs(direction), initial=0.0))
            if big < 1e-12:
                radius = 0.0
                continue
            step = direction * min(1.0, radius / big)
            q_new = wrap_to_pi(q + step, robot.continuous)
            there = model.point(goal, q_new, d_now)
            F_new = there.F
            # keep clearance_floor_m (a tracking arm overshoots a little), unless already closer
            d_new = there.distances_m
            spacious = there.spacious
            if F_new < F_now and spacious and (checker is None or checker.is_valid(q_new)):
                d_now = d_new
                q = q_new
                here = there
                path.append(q.copy())
                radius = min(radius * 1.5, max_step)
                direction, F_now = here.direction, here.F
                f_now = here.f
                held = False
            elif not spacious and not held and s.hold_clearance:
                # the step takes a pair below clearance_floor_m: slide along it instead
                direction = model.hold(goal, q, direction)
                held = True
            else:
                radius *= 0.5
            trace.append(f_now)
            if f_now < best - s.stall_min_decrease:
                best, best_iter = f_now, iteration

    # ------------------------------------------------------------------ goals near q
    def near_goal_state(self, ctx: PlanningContext, q: Array) -> Array | None:
        """A collision-free state in the leg's goal region found by descending F from q
        with the path left unchecked (the clearance term still steers): a goal *near* q,
        the part of the arm that F does not need to move stays where it is. One check.
        The goal finder (:data:`~plannerlab.planners.context.NearGoal`) this descent
        hands its ``rrtconnect`` escape, with its own settings."""
        resolved = self.for_robot(ctx.robot)
        if resolved is not self:
            return resolved.near_goal_state(ctx, q)
        try:
            status, _, path, _, _ = self.leg_descent(ctx, q, checked=False)
        except SetupStopped:  # out of time while building the field: no goal found
            return None
        q_goal = path[-1]
        if status is Status.SOLVED and ctx.checker.is_valid(q_goal):
            return q_goal
        return None

    # ------------------------------------------------------------------ the leg's descent
    def leg_descent(
        self,
        ctx: PlanningContext,
        q_start: Array,
        used: int = 0,
        *,
        checked: bool = True,
    ) -> tuple[Status, str, list[Array], list[float], int]:
        """The descent of one leg: with ``approach_m`` > 0, first to the goal's approach
        point (the tip at ``p_d − approach_m · n_d`` with the goal's normal, within the
        sub-goal tolerances: the tip comes in along the inspection normal), then to the
        goal; if the approach stalls, the descent to the goal continues from there. A goal
        state (:class:`JointGoal`) has no approach point."""
        resolved = self.for_robot(ctx.robot)
        if resolved is not self:
            return resolved.leg_descent(ctx, q_start, used, checked=checked)
        s = self.settings
        goal = ctx.goal
        path = [np.array(q_start)]
        trace: list[float] = []
        iterations = 0
        # a goal state says how the arm comes in: no approach point
        if (
            s.approach_m > 0
            and not isinstance(goal, JointGoal)
            and not goal.contains(ctx.robot, q_start)
        ):
            sub = GoalRegion(
                "approach",
                goal.p_world_m - s.approach_m * goal.n_world,
                goal.n_world,
                s.subgoal_pos_tol_m,
                s.subgoal_angle_tol_deg,
            )
            st, reason, seg, tr, it = self.descend(ctx, path[-1], sub, used, checked=checked)
            iterations += it
            path.extend(seg[1:])
            trace.extend(tr)
            if st not in (Status.SOLVED, Status.LOCAL_MINIMUM):
                return st, reason, path, trace, iterations
        st, reason, seg, tr, it = self.descend(
            ctx, path[-1], None, used + iterations, checked=checked
        )
        path.extend(seg[1:])
        trace.extend(tr)
        return st, reason, path, trace, iterations + it

    # ------------------------------------------------------------------ escapes
    def _detour(
        self,
        ctx: PlanningContext,
        q_stall: Array,
        used: int,
        rng: np.random.Generator | None = None,
    ) -> tuple[list[Array], int, str]:
        """Sub-goals near the stall: the tip drawn back along its own body, to the face
        ``retract_step``, ``2 retract_step``, … modules behind the stall's tip (normal
        along the body), each retract followed by the leg's descent (:meth:`leg_descent`).
        With ``rng`` (``random_detour``) the sub-goals are drawn: each goes back a random
        1 … ``2 retract_step`` modules further, its point uniform in a ball of
        ``retract_jitter_m`` round the face.

        Returns the kept path from q_stall (its last state is in the goal region when the
        detour succeeded, else just [q_stall]), the iterations and how far it retracted.
        """
        s = self.settings
        robot, tracker = ctx.robot, ctx.tracker
        iterations = 0
        # retract along the body of the stall state
        F = robot.fk(q_stall)
        kept = [np.array(q_stall)]
        q = np.array(q_stall)
        last_face = F.shape[0] - 1
        for back in self._retract_depths(robot.dof, rng):
            if tracker.exhausted(used + iterations) is not None:
                break
            face = last_face - back
            p_sub = F[face, :3, 3]
            if rng is not None and s.retract_jitter_m > 0:
                p_sub = p_sub + _in_ball(rng, s.retract_jitter_m)
            sub = GoalRegion(
                f"retract{back}",
                p_sub,
                F[face, :3, 2],
                s.subgoal_pos_tol_m,
                s.subgoal_angle_tol_deg,
            )
            st, _, seg, _, it = self.descend(ctx, q, sub, used + iterations)
            iterations += it
            kept.extend(seg[1:])
            q = kept[-1]
            st2, _, seg2, _, it2 = self.leg_descent(ctx, q, used + iterations)
            iterations += it2
            if st2 is Status.SOLVED:
                return kept + seg2[1:], iterations, f"retract {back} modules"
        return [np.array(q_stall)], iterations, "none"

    def _slide_escape(
        self, ctx: PlanningContext, q0: Array, used: int
    ) -> tuple[list[Array] | None, int, str]:
        """The detours' first escape, from the leg's first stall: the body of the leg's
        start slid back along its own curve until the tip sees the goal's approach point
        (:meth:`_slide`), then the leg's descent. Returns the path from ``q0`` into the
        goal region (None when there is no slide or the descent after it stalls), the
        iterations and how. Only when the start is deep inside
        (:func:`~plannerlab.planners.clearance.slide.deep_inside`). From the start, not
        the stall: the slide's premise is the body as it came in, and the descent that
        stalled has pressed it against a wall (measured: from such stalls the slide
        stalls within 0.5 m on two of three variants, from the start it gets out;
        ``results/leave.md``)."""
        target, clearance, _ = self._slide_target(ctx)
        faces = np.asarray(ctx.robot.fk(q0))[:, :3, 3]
        reach = float(np.sum(np.linalg.norm(np.diff(faces, axis=0), axis=1)))
        if not deep_inside(ctx.scene, faces, target, clearance, reach / 3.0):
            return None, 0, "not deep inside"
        sl = self._slide(ctx, q0, used)
        iterations = sl.iterations
        if sl.status is not Status.SOLVED:
            return None, iterations, sl.reason
        st, _, seg, _, it = self.leg_descent(ctx, sl.states[-1], used + iterations)
        if st is not Status.SOLVED:
            return None, iterations + it, f"{sl.reason}; the descent after it: {st.value}"
        return sl.states + seg[1:], iterations + it, f"slide {sl.slid_m:.2f} m"

    def _slide_target(self, ctx: PlanningContext) -> tuple[Array, float, float]:
        """The slide's target (the goal's approach point; a goal state's tip), the
        clearance its line of sight keeps and the robot's link length [m]."""
        s, robot, goal = self.settings, ctx.robot, ctx.goal
        back = 0.0 if isinstance(goal, JointGoal) else s.approach_m
        link = robot_size(robot).pitch_m
        clearance = sight_clearance_m(robot, ctx.problem.safety_margin_m, link)
        return goal.p_world_m - back * goal.n_world, clearance, link

    def _slide(self, ctx: PlanningContext, q_stall: Array, used: int) -> Slide:
        """The body of ``q_stall`` slid back along its own curve until the tip sees the
        goal's approach point (:func:`~plannerlab.planners.clearance.slide.slide_out`; a
        goal state's: its tip), at the descent's step and clearance floor. Leaving a
        room from its far wall the descent stalls at once, pressing the body against the
        near wall; the tip alone drawn back coils the body inside (``results/leave.md``)."""
        s = self.settings
        target, clearance, link = self._slide_target(ctx)
        return slide_out(
            ctx,
            q_stall,
            target,
            clearance,
            used,
            clearance_floor_m=s.clearance_floor_m,
            max_step_rad=s.max_step_rad if s.max_step_rad > 0 else ctx.problem.joint_step / 2,
            link_m=link,
        )

    def _retract_depths(self, dof: int, rng: np.random.Generator | None) -> list[int]:
        """Modules the detour's sub-goals go back, in order: every ``retract_step`` below
        ``dof``, or (with ``rng``) random steps of 1 … ``2 retract_step``."""
        step = self.settings.retract_step
        if rng is None:
            return list(range(step, dof, step))
        depths: list[int] = []
        back = int(rng.integers(1, 2 * step + 1))
        while back < dof:
            depths.append(back)
            back += int(rng.integers(1, 2 * step + 1))
        return depths

    def _random_detours(
        self,
        ctx: PlanningContext,
        q_stall: Array,
        used: int,
        rng: np.random.Generator,
    ) -> tuple[list[Array], int, str]:
        """Randomly drawn detours from the stall (:meth:`_detour` with ``rng``), drawn again
        while none finds a way, at most ``max_escapes`` draws and within the budget."""
        iterations = 0
        how = "none"
        for draw in range(1, self.settings.max_escapes + 1):
            if ctx.tracker.exhausted(used + iterations) is not None:
                break
            esc, it, how = self._detour(ctx, q_stall, used + iterations, rng)
            iterations += it
            if len(esc) > 1:
                return esc, iterations, f"{how} (draw {draw})"
        return [np.array(q_stall)], iterations, how

    # ------------------------------------------------------------------ solve
    def warm_up(self, problem, leg: int, q_start: Array) -> None:
        """For the compiled backend on an Arm-Z, load (or compile) its kernels before the
        leg's tracker starts, like the checker's core: a one-off cost of the process,
        outside the limits. The problem's field is set-up, built in the solve's time
        (:meth:`model`)."""
        if self.backend_for(problem.robot) == "compiled":
            from plannerlab.planners.clearance.compiled import warm_up

            warm_up()

    def plan(self, ctx: PlanningContext, rng: np.random.Generator) -> PlanResult:
        """Descend F from the context's start into its leg's goal region; at a stall,
        escape from the stall state (``escape`` setting) and descend again."""
        resolved = self.for_robot(ctx.robot)
        if resolved is not self:
            return resolved.plan(ctx, rng)
        s = self.settings
        problem, robot, goal, tracker = ctx.problem, ctx.robot, ctx.goal, ctx.tracker
        q0 = ctx.q_start
        leg_path = LegPath(ctx.run(self.name, s), q0)
        path = leg_path.path
        trace: list[float] = []
        escapes_log: list[dict] = []
        descent_rad: list[float] = []

        def dist(a: Array, b: Array) -> float:
            return float(np.linalg.norm(joint_difference(a, b, robot.continuous)))

        def done(status: Status, reason: str) -> PlanResult:
            """The leg's result from the state of the loop."""
            return leg_path.result(
                status,
                reason,
                trace=trace,
                extra={
                    "descent_rad": descent_rad,
                    "escapes": escapes_log,
                    # what ran: "compiled" falls back to numpy for robots other than Arm-Z
                    "descent_backend": self.backend_for(robot),
                },
            )

        if ctx.start_problem is not None:
            return done(Status.INVALID_START, ctx.start_problem)
        leg_path.note([q0])
        try:  # the set-up, in the leg's time
            self.model(problem, tracker.time_up, ctx.checker)
        except SetupStopped as exc:
            return done(Status.BUDGET_EXHAUSTED, f"{tracker.exhausted() or 'time is up'}: {exc}")
        q = q0
        while True:
            st, reason, seg, tr, it = self.leg_descent(ctx, q, leg_path.iterations)
            leg_path.iterations += it
            trace.extend(tr)
            leg_path.add(seg)
            descent_rad.append(path_length(np.array(seg), robot.continuous))
            minima, escapes = leg_path.minima, leg_path.escapes
            if st is not Status.LOCAL_MINIMUM:  # solved, or out of budget
                return done(st, f"{reason}; {minima} local minima met, {escapes} escaped")
            leg_path.minima = minima = minima + 1
            q_stall = np.array(path[-1])
            if s.escape == "none":
                return done(st, reason)
            if minima > s.max_escapes:
                return done(st, f"{reason}; {minima} local minima met, {escapes} escaped; gave up")
            c0 = tracker.checks_used
            used = leg_path.iterations
            slid = None
            if minima == 1 and s.escape in ("detour", "random_detour"):
                # leaving from deep inside: the body as it came in, slid back out
                slid, it, how = self._slide_escape(ctx, q0, used)
                leg_path.iterations += it
                used = leg_path.iterations
            if slid is not None:
                esc = slid
                del path[1:]  # the leg starts again: the slide starts at its start
            elif s.escape == "detour":
                esc, it, how = self._detour(ctx, q_stall, used)
            elif s.escape == "random_detour":
                esc, it, how = self._random_detours(ctx, q_stall, used, rng)
            else:
                esc, it, how = rrtconnect(self, ctx, q_stall, rng)
            if slid is None:
                leg_path.iterations += it
            if len(esc) <= 1 and s.escape in ("detour", "random_detour"):
                # no retract led into the goal: the tip's route, from the stall
                esc, it, how_route = route(self, ctx, q_stall, leg_path.iterations, rng)
                leg_path.iterations += it
                how = f"no retract led in ({how}); {how_route}"
            left_stall = len(esc) > 1
            leg_path.escapes += int(left_stall)
            escapes_log.append(
                {
                    "kind": s.escape,
                    "how": how,
                    "stall": minima,
                    "start_from_leg_start_rad": dist(esc[0], q0),
                    "start_from_stall_rad": dist(esc[0], q_stall),
                    "descent_before_stall_rad": descent_rad[-1],
                    "left_stall": left_stall,
                    "checks": tracker.checks_used - c0,
                }
            )
            if not left_stall:
                return done(
                    Status.LOCAL_MINIMUM,
                    f"{reason}; the {s.escape} escape from stall {minima} failed ({how})",
                )
            leg_path.add(esc)
            q = np.array(path[-1])
            if goal.contains(robot, q):
                return done(
                    Status.SOLVED,
                    f"descent stalled {minima} times; escaped from the stall by {how}",
                )


def _within(goal: GoalRegion, point, fraction: float) -> bool:
    """Whether the state ``point`` describes is within ``fraction`` of ``goal``'s
    tolerances: the tip's position and angle errors, or for a goal state
    (:class:`JointGoal`) the largest joint difference."""
    if isinstance(goal, JointGoal):
        return bool(point.joint_err <= fraction * goal.tol_rad)
    return bool(
        point.pos_err_m <= fraction * goal.pos_tol_m
        and point.ang_err_deg <= fraction * goal.angle_tol_deg
    )


def _in_ball(rng: np.random.Generator, radius_m: float) -> Array:
    """A point drawn uniformly in the ball of ``radius_m`` round the origin (3,) [m]."""
    v = rng.normal(size=3)
    v /= max(float(np.linalg.norm(v)), 1e-12)
    return v * radius_m * float(rng.uniform()) ** (1.0 / 3.0)


VARIANTS: dict[str, dict[str, object]] = {
    "gradient.clearance": {},
    "gradient.clearance+detour": {"escape": "detour"},
    "gradient.clearance+random_detour": {"escape": "random_detour"},
    "gradient.clearance+rrtconnect": {"escape": "rrtconnect"},
}


def make(
    name: str,
    overrides: dict,
    *,
    escape_planner: Callable[[Mapping[str, Any]], Planner] | None = None,
    route_planner: Callable[[Mapping[str, Any]], Planner] | None = None,
) -> ClearanceDescent:
    """Registry factory for the ``gradient.clearance`` family. ``escape_planner(overrides)``
    makes the RRT-Connect planner of the ``rrtconnect`` escape (the registry passes OMPL's,
    so this module needs neither the registry nor ``ompl``); ``route_planner(overrides)``
    makes follow-the-leader for the detours' route escape (``route_escape``)."""
    if name not in VARIANTS:
        raise PlannerlabError(f"{name} is not a clearance descent ({', '.join(VARIANTS)})")
    base = ClearanceSettings(**VARIANTS[name])  # type: ignore[arg-type]
    return ClearanceDescent(
        name, with_overrides(base, overrides, name), escape_planner, route_planner
    )
