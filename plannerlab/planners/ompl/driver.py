"""One OMPL solve of one leg, from the goal pool to the re-checked path: the driver.

:class:`Solve` builds the solve's OMPL objects (the space, the space information with the
guarded validity checker and motion validator, the goal, the problem definition, the
planner with its settings), plans until a limit or a held path's reserve stops it, then
simplifies, densifies and re-checks the path (see the package docstring: the reserve, the
time limit, the hard stop). Every OMPL object lives in one :class:`Solve` and is dropped by
:meth:`Solve.close`.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
import ompl.base as ob
import ompl.geometric as og

from plannerlab.planners.base import PlanResult, Status
from plannerlab.planners.context import PlanningContext
from plannerlab.planners.ompl.goal import fill_goal_pool, goal_class
from plannerlab.planners.ompl.guard import Guard, TimeUp
from plannerlab.planners.ompl.repair import repair
from plannerlab.planners.ompl.roadmap import roadmap_solve
from plannerlab.planners.ompl.settings import (
    CHUNK_STATES,
    HARD_STOP,
    KPIECE,
    LIFTED,
    RESERVE_EVERY_POLLS,
    RESERVE_FACTOR,
    ROADMAP,
    SETTERS,
    SIMPLIFY_MAX_STATES,
    STOP_ON_FIRST,
    TIME_SLACK,
    OMPLSettings,
)
from plannerlab.planners.ompl.space import Space, goal_chain, reach_m, tip_projection
from plannerlab.problem.goals import GoalRegion
from plannerlab.robots.base import Array, joint_difference, wrap_to_pi
from plannerlab.robots.paths import path_length


def recheck_cost(path: Array, joint_step: float, checker: Any) -> int:
    """Collision checks ``checker.check_path(path, joint_step)`` will make at most (all
    states of the path as the checker densifies it, metric edge resolution included;
    conservative advancement makes no more), computed without checking anything."""
    return int(checker.grid_states(path, joint_step))


class Solve:
    """One OMPL solve of the leg of ``ctx`` by OMPL's ``ompl_class`` (see the module
    docstring).

    Args:
        name: the planner's registry name; ``ompl_class`` its OMPL class; ``settings``.
        ctx: the leg's context; ``guard`` its guarded checker and termination condition.
        rng: the trial's generator (the IK pool); ``ompl_seed`` the seed in effect.
    """

    def __init__(
        self,
        name: str,
        ompl_class: str,
        settings: OMPLSettings,
        ctx: PlanningContext,
        guard: Guard,
        rng: np.random.Generator,
        ompl_seed: int,
    ) -> None:
        self.name, self.ompl_class, self.s = name, ompl_class, settings
        self.ctx, self.guard, self.rng = ctx, guard, rng
        self.robot, self.goal = ctx.robot, ctx.goal
        self.checker, self.tracker = guard.checker, guard.tracker
        self.max_checks = self.tracker.budget.max_collision_checks
        self.time_limit = self.tracker.budget.time_limit_s
        self.q0 = wrap_to_pi(ctx.q_start.reshape(self.robot.dof), self.robot.continuous)
        self.recheck_step = ctx.joint_step / 4.0
        self.fk = [0]  # FK calls (the goal distance's, the projection's)
        self.trace: list[float] = []
        self.run = ctx.run(name, settings)
        self.progress = self.run.progress
        self.extra: dict[str, Any] = {"ompl_class": ompl_class, "ompl_seed": ompl_seed}
        self.pool: list[Array] = []
        #: the path the check reserve holds (waypoints, start first) and its re-check cost
        self.held: Array | None = None
        self.held_cost = 0
        self.best_seen = math.inf
        self.stopped = False
        # OMPL objects, built by _build and dropped by close
        self.space: Any = None
        self.si: Any = None
        self.pdef: Any = None
        self.goal_obj: Any = None
        self.planner: Any = None
        self.motion_validator: Any = None
        #: the found path before simplification (the repair's first step)
        self.unsimplified: Any = None

    # ------------------------------------------------------------------ the solve
    def result(self, status: Status, reason: str, path: Array, iterations: int) -> PlanResult:
        """The leg's result, with the counts of the solve so far."""
        self.extra["refused_checks"] = self.guard.refused
        return self.run.result(
            status,
            reason,
            path,
            iterations=iterations,
            fk_calls=self.fk[0],
            trace=self.trace,
            extra=self.extra,
        )

    def solve(self) -> PlanResult:
        """Plan the leg: the goal pool, the search, then the path's simplification and
        re-check."""
        ctx, q0 = self.ctx, self.q0
        if ctx.start_problem is not None:
            return self.result(Status.INVALID_START, ctx.start_problem, q0[None], 0)
        self.fk[0] += 1
        self.progress.note(float(self.goal.distance(self.robot, q0)))  # the search's start
        self.pool, pool_cut_short = fill_goal_pool(
            ctx, self.s, self.guard, self.rng, q0, self.extra
        )
        c_planning = self.checker.checks
        self._build()
        found = self._search()
        if isinstance(found, PlanResult):
            return found
        ompl_path, exact, status_text = found
        iterations = self.guard.iterations()
        self.extra["ompl_status"] = status_text
        self.extra["planning_checks"] = self.checker.checks - c_planning
        why_stopped = self.guard.exhausted()
        if ompl_path is None:
            return self._no_path(pool_cut_short, status_text, why_stopped, iterations)
        path = self._path_to_check(ompl_path, status_text, iterations)
        if isinstance(path, PlanResult):
            return path
        return self._checked(path, exact, status_text, why_stopped, iterations)

    def close(self) -> None:
        """Drop every OMPL object of the solve (Python callbacks held by them reference
        this solve: break the cycle so that they are freed with it)."""
        self.guard.iteration_source = None
        self.planner = self.pdef = self.goal_obj = self.si = None
        self.motion_validator = self.space = self.unsimplified = None

    # ------------------------------------------------------------------ building
    def _build(self) -> None:
        """The space, the space information (guarded validity checker, motion validator),
        the goal on the pool, the problem definition and the OMPL planner."""
        s, guard, robot, goal, q0 = self.s, self.guard, self.robot, self.goal, self.q0
        space = Space(robot, lifted=self.ompl_class in LIFTED, center=q0)
        self.space = space
        self.extra["state_space"] = (
            "lifted_real_vector"
            if space.lifted
            else "so2_compound"
            if space.compound
            else "real_vector"
        )
        si = ob.SpaceInformation(space.space)

        def state_valid(state: Any) -> bool:
            return guard.is_valid(space.to_q(state))

        si.setStateValidityChecker(state_valid)
        joint_step = self.ctx.joint_step
        extent = space.space.getMaximumExtent()
        si.setStateValidityCheckingResolution(min(joint_step / extent, 1.0))
        if s.motion_check == "batched":

            class EdgeValidator(ob.MotionValidator):
                def checkMotion(self, a: Any, b: Any) -> bool:  # noqa: N802
                    return guard.edge_valid(space.to_q(a), space.to_q(b), joint_step)

            self.motion_validator = EdgeValidator(si)
            si.setMotionValidator(self.motion_validator)
        si.setup()
        self.si = si

        best = [math.inf]
        fk, trace, progress, pool = self.fk, self.trace, self.progress, self.pool
        tip = self.checker.tip  # compiled kinematics where the checker has them
        # a goal whose distance is GoalRegion's (the tip's) takes the compiled tip; a goal
        # with a distance of its own (a joint goal, say) is asked as it is
        by_tip = type(goal).distance is GoalRegion.distance

        def distance(state: Any) -> float:
            fk[0] += 1
            q = space.to_q(state)
            d = float(goal.distance_from_tip(*tip(q)) if by_tip else goal.distance(robot, q))
            if d < best[0]:
                best[0] = d
                trace.append(d)
                progress.note(d)
            return d

        def fill(state: Any, i: int) -> None:
            space.set_state(state, pool[i])

        self.goal_obj = goal_class()(si, distance, fill, len(pool))
        pdef = ob.ProblemDefinition(si)
        start = space.space.allocState()
        space.set_state(start, q0)
        pdef.addStartState(start)
        pdef.setGoal(self.goal_obj)
        self.pdef = pdef
        self.planner = self._ompl_planner()
        self.planner.setProblemDefinition(pdef)
        self.planner.setup()

    def _ompl_planner(self) -> Any:
        """OMPL's planner on the space information, with the settings it has setters for,
        the KPIECE family's tip projection, and where its iterations are counted."""
        s, robot = self.s, self.robot
        planner = getattr(og, self.ompl_class)(self.si)
        for field in dataclasses.fields(s):
            setter = SETTERS.get(field.name)
            if setter is not None and hasattr(planner, setter):
                getattr(planner, setter)(getattr(s, field.name))
        if self.ompl_class in KPIECE:
            reach = reach_m(robot, self.q0)
            cell = s.projection_cell_m or reach / 20.0  # type: ignore[attr-defined]
            self.extra["projection_cell_m"] = cell
            planner.setProjectionEvaluator(
                tip_projection(self.space, cell, robot.T_world_base[:3, 3], reach, self.fk)
            )
        if hasattr(planner, "numIterations"):
            self.guard.iteration_source = planner.numIterations
        elif self.ompl_class in ROADMAP:
            self.guard.iteration_source = planner.milestoneCount
        return planner

    # ------------------------------------------------------------------ paths and the reserve
    def rows_of(self, ompl_path: Any) -> Array:
        """The path that will be re-checked: interpolated (if set), wrapped, from q0."""
        if self.s.interpolate:
            ompl_path = og.PathGeometric(ompl_path)
            ompl_path.interpolate()
        n = ompl_path.getStateCount()
        Q = wrap_to_pi(
            np.array([self.space.to_q(ompl_path.getState(i)) for i in range(n)]),
            self.robot.continuous,
        )
        if len(Q):
            Q[0] = self.q0
        return Q

    def recheck_cost_of(self, ompl_path: Any) -> int:
        return recheck_cost(self.rows_of(ompl_path), self.recheck_step, self.checker)

    def ompl_path_of(self, Q: Array) -> Any:
        """An OMPL path through the waypoints Q (k, dof) (states copied in)."""
        p = og.PathGeometric(self.si)
        st = self.space.space.allocState()
        for q in Q:
            self.space.set_state(st, q)
            p.append(st)  # appends a copy
        return p

    def waypoints_of(self, ompl_path: Any) -> Array:
        return np.array(
            [self.space.to_q(ompl_path.getState(i)) for i in range(ompl_path.getStateCount())]
        )

    def hold(self, Q: Array) -> bool:
        """Hold back the re-check cost of the path through Q, if it fits the checks not
        yet spent: from now on planning cannot spend them (the guard refuses), so this
        path (or a better one that fits) can always be re-checked within the budget."""
        cost = self.recheck_cost_of(self.ompl_path_of(Q))
        left = self.tracker.checks_left()
        if left is not None and cost > left:
            return False
        self.held, self.held_cost = Q, cost
        self.guard.reserve = cost if left is not None else 0
        self.extra.setdefault("reserve_held_at_checks", self.tracker.checks_used)
        self.extra["reserve_checks"] = cost
        return True

    def tree_best_path(self) -> Array | None:
        """The best path of an optimizing planner's tree (RRT*, Informed RRT*, BIT*:
        they hand their path to the problem definition only when they stop): the chain
        of parents from its goal vertex to the start, from OMPL's planner data."""
        data = ob.PlannerData(self.si)
        try:
            self.planner.getPlannerData(data)
            return goal_chain(data, self.space)
        finally:
            data.clear()

    def past_time(self) -> bool:
        """The steps after planning are over the time limit (+ its slack)."""
        tl = self.time_limit
        return tl is not None and self.tracker.elapsed_s > tl * (1.0 + TIME_SLACK)

    # ------------------------------------------------------------------ searching
    def planning_done(self) -> bool:
        """Any limit reached, or a path is held and the checks left are its reserve
        (asymptotically optimal planners would otherwise spend the whole budget
        improving it)."""
        guard, planner, tracker = self.guard, self.planner, self.tracker
        if guard.poll():
            return True
        if self.max_checks is None and self.time_limit is None:
            return False
        due = self.held is None or guard.polls % RESERVE_EVERY_POLLS == 0
        if self.ompl_class in STOP_ON_FIRST:
            pass  # its first path is held when its first solve returns (_search)
        elif hasattr(planner, "bestCost"):
            best = float(planner.bestCost().value())
            if math.isfinite(best) and best < self.best_seen and due:
                self.best_seen = best  # read the tree once per improvement
                Q = self.tree_best_path()
                if Q is not None:
                    self.hold(Q)
        elif self.pdef.hasSolution() and due:
            self.hold(self.waypoints_of(og.PathGeometric(self.pdef.getSolutionPath())))
        if self.held is None:
            return False
        if self.time_limit is not None:
            # the re-check's time at this solve's own rate (planning overhead included)
            rate_s = tracker.elapsed_s / max(tracker.checks_used, 1)
            if tracker.elapsed_s + RESERVE_FACTOR * self.held_cost * rate_s >= self.time_limit:
                return True
        left = guard.checks_left()
        return left is not None and left <= 0

    def planning_done_once(self) -> bool:
        """:meth:`planning_done`, remembered (a planner that returns on an improvement
        is resumed only if its termination condition did not stop it)."""
        self.stopped = self.stopped or self.planning_done()
        return self.stopped

    def _search(self) -> tuple[Any, bool, str] | PlanResult:
        """Run the OMPL planner: its path (an OMPL path or None), whether it is exact,
        OMPL's status in words; a result when a hard stop ended it."""
        planner, pdef, guard = self.planner, self.pdef, self.guard
        if self.ompl_class in STOP_ON_FIRST:
            planner.setStopOnSolnImprovement(True)
        ptc = ob.PlannerTerminationCondition(self.planning_done_once)
        if self.ompl_class in ROADMAP:
            return roadmap_solve(
                planner, self.s, self.si, self.space, guard, self.pool, self.q0, self.ctx.joint_step
            )
        guard.hard_stop = self.ompl_class in HARD_STOP
        exact_kind = ob.PlannerStatus.PlannerStatusType.EXACT_SOLUTION
        try:
            status = planner.solve(ptc)
            if (
                self.ompl_class in STOP_ON_FIRST
                and status.getStatus() == exact_kind
                and pdef.hasSolution()
                and not self.stopped
            ):
                # it returned on its first path: hold it, then resume the search
                self.hold(self.waypoints_of(og.PathGeometric(pdef.getSolutionPath())))
                planner.setStopOnSolnImprovement(False)
                status = planner.solve(ptc)
        except TimeUp:
            return self.result(
                Status.BUDGET_EXHAUSTED,
                f"{self.ompl_class}: time limit of {self.time_limit:g} s reached (stopped "
                "inside its expansion, which polls no termination condition)",
                self.q0[None],
                guard.iterations(),
            )
        finally:
            guard.hard_stop = False
        kind = status.getStatus()
        exact = kind == exact_kind
        usable = exact or kind == ob.PlannerStatus.PlannerStatusType.APPROXIMATE_SOLUTION
        ompl_path = (
            og.PathGeometric(pdef.getSolutionPath()) if usable and pdef.hasSolution() else None
        )
        return ompl_path, exact, status.asString()

    def _no_path(
        self, pool_cut_short: str, status_text: str, why_stopped: str | None, iterations: int
    ) -> PlanResult:
        """The result of a search that found no path."""
        q0 = self.q0
        if not self.pool and pool_cut_short:
            return self.result(
                Status.BUDGET_EXHAUSTED,
                f"the budget ran out while sampling goal states by IK ({pool_cut_short}) "
                f"and {self.ompl_class} reached no goal: give a larger budget",
                q0[None],
                iterations,
            )
        if not self.pool:
            return self.result(
                Status.INVALID_GOAL,
                f"IK found no valid goal state in {self.s.max_goal_attempts} "
                f"attempts and {self.ompl_class} reached none "
                f"({status_text}; {why_stopped or 'no limit hit'})",
                q0[None],
                iterations,
            )
        return self.result(
            Status.BUDGET_EXHAUSTED if why_stopped else Status.FAILED,
            f"{self.ompl_class}: {status_text}" + (f"; {why_stopped}" if why_stopped else ""),
            q0[None],
            iterations,
        )

    # ------------------------------------------------------------------ after the search
    def _simplify(self, simplified: Any) -> None:
        """OMPL's PathSimplifier on ``simplified`` (in place), within the budget: it stops
        at any limit, or once only the held path's reserve is left; with no path held yet
        (its re-check did not fit), once the simplified path's re-check fits, it is held.
        OMPL's simplify runs one whole pass whatever the termination condition says, and
        its collapseCloseVertices compares every vertex pair at each of up to n steps
        without polling it: on the chain of hundreds of tiny edges an optimizing planner's
        dense tree gives (cheap edge checks make dense trees), that pass takes minutes.
        Such a path is thinned first by reduceVertices (random shortcuts, each a checked
        motion), and left as it is if it stays long."""
        guard = self.guard

        def simplify_done() -> bool:
            if guard.poll():
                return True
            if self.max_checks is None:
                return False
            if self.held is None:
                self.hold(self.waypoints_of(simplified))
            left = guard.checks_left()
            return left is not None and left <= 0

        simplifier = og.PathSimplifier(self.si, self.goal_obj)
        c0 = self.checker.checks
        thinning = 0
        while (
            simplified.getStateCount() > SIMPLIFY_MAX_STATES
            and thinning < 20
            and not simplify_done()
        ):
            simplifier.reduceVertices(simplified)
            thinning += 1
        if thinning:
            self.extra["thinning_passes"] = thinning
        if simplified.getStateCount() <= SIMPLIFY_MAX_STATES:
            simplifier.simplify(simplified, ob.PlannerTerminationCondition(simplify_done))
        self.extra["simplify_checks"] = self.checker.checks - c0

    def _path_to_check(
        self, ompl_path: Any, status_text: str, iterations: int
    ) -> Array | PlanResult:
        """The found path, simplified (or the held one, whose re-check fits), densified
        and wrapped, from q0 exactly; a result when it cannot be re-checked."""
        extra, robot, q0 = self.extra, self.robot, self.q0
        extra["length_raw"] = float(ompl_path.length())
        extra["waypoints_raw"] = int(ompl_path.getStateCount())
        if self.max_checks is not None:
            # the path to re-check: the final one if its re-check fits the checks left, else
            # the best one held during planning (whose re-check always fits)
            self.hold(self.waypoints_of(ompl_path))
            if self.held is not None:
                ompl_path = self.ompl_path_of(self.held)
        simplified = og.PathGeometric(ompl_path)
        self.unsimplified = og.PathGeometric(ompl_path)  # for the repair (repair.py)
        if self.s.simplify and self.guard.exhausted() is None:
            self._simplify(simplified)
        left = self.tracker.checks_left()
        if left is None or self.recheck_cost_of(simplified) <= left:
            ompl_path = simplified
        elif self.held is not None:  # simplifying made the re-check dearer: the held one
            ompl_path = self.ompl_path_of(self.held)
            extra["simplified_path_dropped"] = True
        else:
            cost = self.recheck_cost_of(simplified)
            extra["validation_checks"] = 0
            return self.result(
                Status.BUDGET_EXHAUSTED,
                f"{self.ompl_class} found a path ({status_text}) but re-checking it at "
                f"joint_step/4 needs {cost} collision checks and the budget of "
                f"{self.max_checks} leaves {left}: the path is not trusted; give a larger "
                "--max-checks",
                self.waypoints_of(simplified),
                iterations,
            )
        extra["length_simplified"] = float(ompl_path.length())
        extra["waypoints_simplified"] = int(ompl_path.getStateCount())
        waypoints = wrap_to_pi(self.waypoints_of(ompl_path), robot.continuous)
        if self.guard.out_of_time():  # a path found at the limit: no time left to densify
            return self._out_of_time(status_text, waypoints, iterations)
        if self.s.interpolate:
            ompl_path.interpolate()
        rows: list[Array] = []
        for i in range(ompl_path.getStateCount()):
            if i % CHUNK_STATES == 0 and self.past_time():
                return self._out_of_time(status_text, waypoints, iterations)
            rows.append(self.space.to_q(ompl_path.getState(i)))
        path = wrap_to_pi(np.array(rows), robot.continuous)
        if float(np.max(np.abs(joint_difference(path[0], q0, robot.continuous)))) > 1e-6:
            return self.result(
                Status.FAILED,
                f"{self.ompl_class} returned a path that does not "
                f"start at the start state ({status_text})",
                q0[None],
                iterations,
            )
        path[0] = q0  # exact copy (removes float noise of the OMPL round trip)
        extra["path_length_rad"] = path_length(path, robot.continuous)
        return path

    def _checked(
        self,
        path: Array,
        exact: bool,
        status_text: str,
        why_stopped: str | None,
        iterations: int,
    ) -> PlanResult:
        """The path re-checked at ``joint_step / 4`` within the budget (+1 %) and the
        time limit (+ its slack): solved, approximate, or why it is not trusted."""
        extra, checker, max_checks = self.extra, self.checker, self.max_checks
        cost = recheck_cost(path, self.recheck_step, checker)
        if max_checks is not None:
            left = max_checks + max_checks // 100 - self.tracker.checks_used
            if cost > left:
                extra["validation_checks"] = 0
                return self.result(
                    Status.BUDGET_EXHAUSTED,
                    f"{self.ompl_class} found a path ({status_text}) but re-checking it at "
                    f"joint_step/4 needs {cost} collision checks and the budget of "
                    f"{max_checks} (+1 %) leaves {max(left, 0)}: the path is not "
                    "trusted; give a larger --max-checks",
                    path,
                    iterations,
                )
        c0 = checker.checks
        check = checker.check_path(path, self.recheck_step, stop=self.past_time, chunk=CHUNK_STATES)
        extra["validation_checks"] = checker.checks - c0
        if not check.complete:
            return self._out_of_time(status_text, path, iterations)
        if not check.valid:
            failed = (
                f"{self.ompl_class} path fails the re-check at joint_step/4 on "
                f"edge {check.first_invalid_edge}: "
                + ", ".join(f"{a} x {b}" for a, b in check.pairs)
            )
            extra["recheck_failed"] = failed
            c0 = checker.checks
            fixed = repair(self, self.unsimplified, replan=exact)
            extra["repair_checks"] = checker.checks - c0
            if fixed is None and self.past_time():
                return self._out_of_time(status_text, path, iterations)
            if fixed is None:
                return self.result(
                    Status.INVALID_PATH, f"{failed}; repair: {extra['repair']}", path, iterations
                )
            path = fixed
            extra["path_length_rad"] = path_length(path, self.robot.continuous)
        if exact and bool(self.goal.contains(self.robot, path[-1])):
            return self.result(Status.SOLVED, f"{self.ompl_class}: {status_text}", path, iterations)
        return self.result(
            Status.APPROXIMATE,
            f"{self.ompl_class}: {status_text}; ends outside the goal region"
            + (f" ({why_stopped})" if why_stopped else ""),
            path,
            iterations,
        )

    def _out_of_time(self, status_text: str, path: Array, iterations: int) -> PlanResult:
        """The time limit (+ its slack) ran out after planning, before the path's re-check
        finished: the path is not trusted."""
        return self.result(
            Status.BUDGET_EXHAUSTED,
            f"{self.ompl_class} found a path ({status_text}) but the time limit of "
            f"{self.time_limit:g} s (+{TIME_SLACK:.0%}) ran out before its re-check at "
            "joint_step/4 finished: the path is not trusted; give a larger --time-limit",
            path,
            iterations,
        )
