"""The ``trajopt.*`` planners: :class:`TrajOptPlanner` (seeds, the optimisation, the
re-check, densify and re-optimise) and :func:`make`, the registry's factory.

One leg:

1. The geometry (:class:`~plannerlab.planners.trajopt.geometry.PathGeometry`) on the
   checker's compiled model, in the leg's time.
2. For each seed of ``seeds`` in order (:mod:`~plannerlab.planners.trajopt.seeds`), and
   for each of its paths: the path resampled at ``coarse_factor · waypoint_m`` of motion
   (the first pass, on few waypoints), optimised
   (:func:`~plannerlab.planners.trajopt.solvers.optimise`); if that finds no feasible
   path, the seed resampled at ``waypoint_m``; then up to ``restarts`` times from that
   bent by a random bump, until one optimisation succeeds.
3. **No tunnelling.** An optimised path that is feasible at its evaluated states is
   re-checked as every planner's path is: ``checker.check_path(path, joint_step / 4,
   mode="grid")``, the problem's margin, every state of the grid. If it refuses an edge,
   the grid states of every later edge are checked too, and each refused edge and its
   neighbours are split in two (waypoints are added only there) and the path is
   optimised again from where it was, at most ``max_refines`` times. Only a path that
   passes is returned as solved.
4. If no optimisation succeeds but a seed planner's path did (``rrtconnect``, ``leader``:
   re-checked by that planner), that path is returned, solved, with
   ``extra["optimised"] = False``.

Budgets: every merit evaluation is an iteration and charges its evaluated states as
collision checks (a state's sphere distances: one check); the re-check's checks are the
checker's; a seed planner's iterations and checks are the leg's (a sub-solve). The
optimisation stops when a limit is reached or when the checks left would not pay for
the path's re-check (it may use 1 % beyond the budget, as every planner's).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from plannerlab.errors import PlannerlabError
from plannerlab.planners.base import PlanResult, Status, with_overrides
from plannerlab.planners.clearance.field import SetupStopped
from plannerlab.planners.context import LegPlanner, PlanningContext
from plannerlab.planners.trajopt.path import PathProblem
from plannerlab.planners.trajopt.seeds import (
    Seed,
    bumped,
    goal_states,
    planner_seed,
    resample,
)
from plannerlab.planners.trajopt.settings import TrajOptSettings
from plannerlab.planners.trajopt.solvers import BudgetStop, Work, optimise
from plannerlab.robots.base import Array, wrap_to_pi
from plannerlab.robots.paths import path_length, roughness

__all__ = ["TrajOptPlanner", "make"]

#: the re-check may run this fraction past the time limit and the check budget
SLACK = 0.01
#: the re-check's states between two looks at the clock
RECHECK_CHUNK = 4096


class _Guard:
    """The goal pool's checker behind the leg's tracker (what ``fill_goal_pool`` asks)."""

    def __init__(self, checker: Any, solve: _Solve) -> None:
        self.checker, self.solve = checker, solve

    def exhausted(self) -> str | None:
        return self.solve.exhausted()

    def out_of_time(self) -> bool:
        return self.solve.tracker.time_up()

    def is_valid(self, q: Array) -> bool:
        left = self.solve.tracker.checks_left()
        if (left is not None and left <= 0) or self.out_of_time():
            return False
        return bool(self.checker.is_valid(q))


@dataclass
class _Solve:
    """One leg's solve (see the module docstring)."""

    planner: TrajOptPlanner
    s: TrajOptSettings
    ctx: PlanningContext
    rng: np.random.Generator
    iterations: int = 0
    extra: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        ctx = self.ctx
        self.robot, self.goal, self.checker, self.tracker = (
            ctx.robot,
            ctx.goal,
            ctx.checker,
            ctx.tracker,
        )
        self.cont = np.asarray(self.robot.continuous, dtype=bool)
        self.q0 = wrap_to_pi(np.asarray(ctx.q_start, dtype=float), self.cont)
        self.run = ctx.run(self.planner.name, self.s)
        self.step = ctx.joint_step / 4.0  # the re-check's
        self.lower = np.where(self.cont, -np.inf, np.asarray(self.robot.lower, dtype=float))
        self.upper = np.where(self.cont, np.inf, np.asarray(self.robot.upper, dtype=float))
        self.reserve = 0  # checks kept for the current path's re-check

    # ------------------------------------------------------------------ budget
    def exhausted(self, more_checks: int = 0) -> str | None:
        """Why to stop (None: go on) before work that costs ``more_checks`` checks."""
        why = self.tracker.exhausted(self.iterations)
        if why:
            return why
        left = self.tracker.checks_left()
        if left is not None and left < more_checks + self.reserve:
            return (
                f"collision-check budget of {self.tracker.budget.max_collision_checks} used "
                "up (the rest is the path's re-check)"
            )
        return None

    def work(self) -> Work:
        def stop(states: int) -> str | None:
            return self.exhausted(states)

        def charge(states: int) -> None:
            self.iterations += 1
            self.tracker.charge_checks(states)

        return Work(stop=stop, charge=charge)

    def result(self, status: Status, reason: str, path: Array) -> PlanResult:
        return self.run.result(status, reason, path, iterations=self.iterations, extra=self.extra)

    # ------------------------------------------------------------------ the leg
    def solve(self) -> PlanResult:
        q0, s = self.q0, self.s
        start = self.q0[None]
        if self.ctx.start_problem is not None:
            return self.result(Status.INVALID_START, self.ctx.start_problem, start)
        self.run.progress.note(float(self.goal.distance(self.robot, q0)))
        try:
            from plannerlab.planners.trajopt.geometry import problem_geometry

            # the sphere field on the checker's compiled model, built once per checker
            # (the first leg of a trial builds it in its time; the others reuse it)
            self.geometry = problem_geometry(self.checker, self.tracker.time_up)
        except ValueError as e:
            raise PlannerlabError(
                f"{self.planner.name}: no compiled model of this problem: {e}"
            ) from e
        except SetupStopped as e:
            limit = self.tracker.budget.time_limit_s
            return self.result(
                Status.BUDGET_EXHAUSTED,
                f"{self.planner.name}: time limit of {limit:g} s reached while building the "
                f"sphere field ({e})",
                start,
            )
        reach = self.checker.reach_m
        self.reach = None if reach is None else np.asarray(reach, dtype=float)
        self.extra.update(seeds=[], attempts=0)
        fallback: Seed | None = None
        last = "no seed gave a path to optimise"
        for name in s.seed_list:
            for seed in self.seeds(name):
                if isinstance(seed, PlanResult):  # out of budget
                    return self._finish(fallback, seed.reason, seed)
                if seed.result is not None and fallback is None:
                    fallback = seed
                out = self.optimise_seed(seed)
                if isinstance(out, PlanResult):
                    if out.status is Status.SOLVED:
                        return out
                    return self._finish(fallback, out.reason, out)
                last = out
        return self._finish(fallback, last, None)

    def _finish(self, fallback: Seed | None, why: str, stopped: PlanResult | None) -> PlanResult:
        """No optimised path: the seed planner's path when there is one, else why not."""
        if fallback is not None and fallback.result is not None:
            self.extra["optimised"] = False
            path = wrap_to_pi(fallback.path, self.cont)
            path[0] = self.q0
            return self.result(
                Status.SOLVED,
                f"{self.planner.name}: no optimised path ({why}); the {fallback.name} seed's "
                "path, re-checked by its planner",
                fallback.result.path,
            )
        if stopped is not None:
            return stopped
        return self.result(Status.FAILED, f"{self.planner.name}: {why}", self.q0[None])

    # ------------------------------------------------------------------ seeds
    def seeds(self, name: str) -> Any:
        """The seeds named ``name`` (a generator: each is made when it is needed), or a
        result when the budget ran out making them."""
        s, ctx, q0 = self.s, self.ctx, self.q0
        if name in ("rrtconnect", "leader", "gradient"):
            planner = self.planner.seed_planners[name]
            seed, r = planner_seed(name, planner, ctx, self.rng, q0, s.seed_share)
            self.extra["seeds"].append(
                {"seed": name, "status": None if r is None else r.status.value}
            )
            if seed is None:
                if r is None or r.status is Status.BUDGET_EXHAUSTED:
                    # the leg's budget (or the seed's share of it) ran out in the seed
                    why = "the budget was used up" if r is None else r.reason
                    yield self.result(
                        Status.BUDGET_EXHAUSTED,
                        f"{self.planner.name}: the {name} seed found no path ({why})",
                        self.q0[None],
                    )
                return
            if name == "gradient" and not bool(self.goal.contains(self.robot, seed.path[-1])):
                goals = self.goal_states(seed.path[-1])
                if isinstance(goals, PlanResult):
                    yield goals
                    return
                if not goals:
                    return
                end = seed.path[-1]
                near = min(goals, key=lambda g: float(np.sum((g - end) ** 2)))
                seed = Seed(name, np.vstack([seed.path, near[None]]))
            yield seed
            return
        goals = self.goal_states(q0)
        if isinstance(goals, PlanResult):
            yield goals
            return
        self.extra["seeds"].append({"seed": "line", "goal_states": len(goals)})
        for g in goals:
            yield Seed("line", np.vstack([q0, g]))

    def goal_states(self, q_near: Array) -> list[Array] | PlanResult:
        """The goal states, unwrapped next to ``q_near`` (the pool is filled once)."""
        if not hasattr(self, "_goals"):
            goals, cut = goal_states(
                self.ctx, self.s, self.rng, self.q0, self.extra, _Guard(self.checker, self)
            )
            if not goals and cut:
                return self.result(
                    Status.BUDGET_EXHAUSTED,
                    f"the budget ran out while sampling goal states by IK ({cut})",
                    self.q0[None],
                )
            self._goals = [wrap_to_pi(g, self.cont) for g in goals]
        from plannerlab.robots.base import joint_difference

        return [q_near + joint_difference(g, q_near, self.cont) for g in self._goals]

    # ------------------------------------------------------------------ optimisation
    def optimise_seed(self, seed: Seed) -> PlanResult | str:
        """The seed optimised, then its restarts: a solved result, a result that ends the
        leg (the budget), or why none worked."""
        s = self.s
        reach = self.reach
        if reach is None:  # no margin: the geometry's speeds along the seed
            P = seed.path
            reach = self.geometry.speeds(P[:: max(len(P) // 16, 1)])
        # the first pass on coarse waypoints (the re-check adds waypoints where it
        # refuses); if it finds no feasible path, the seed at waypoint_m, then restarts
        X0 = resample(seed.path, reach, s.waypoint_m, s.min_waypoints, s.max_waypoints)
        first = [X0]
        if s.coarse_factor > 1:
            spacing = s.waypoint_m * s.coarse_factor
            Xc = resample(seed.path, reach, spacing, s.min_waypoints, s.max_waypoints)
            if len(Xc) < len(X0):
                first.insert(0, Xc)
        why = ""
        for attempt in range(len(first) + s.restarts):
            X = (
                first[attempt]
                if attempt < len(first)
                else bumped(X0, self.rng, s.restart_sigma_rad, self.lower, self.upper)
            )
            self.extra["attempts"] += 1
            self.extra.update(seed=seed.name, attempt=attempt)
            out = self.optimise_path(X)
            if isinstance(out, PlanResult):
                return out
            why = f"{seed.name} seed, attempt {attempt} ({len(X)} waypoints): {out}"
        return why

    def optimise_path(self, X: Array) -> PlanResult | str:
        """X (K, dof) optimised, re-checked, refined: a result (solved, or the budget
        ended the leg), or why it failed."""
        s = self.s
        mu = s.penalty_start
        self.extra.update(first_pass_waypoints=len(X), refined_edges=[])
        for refine in range(s.max_refines + 1):
            problem = PathProblem(
                self.geometry,
                self.robot,
                self.goal,
                len(X),
                s.substeps,
                self.ctx.margin_m,
                s.buffer_m,
                s.smooth_weight,
                s.goal_weight,
                s.goal_depth,
            )
            self.reserve = int(self.checker.grid_states(wrap_to_pi(X, self.cont), self.step))
            try:
                out = optimise(problem, X, s.penalty, self.work(), mu)
            except BudgetStop as stop:
                return self.result(Status.BUDGET_EXHAUSTED, str(stop), self.q0[None])
            if not out.feasible:
                return out.reason
            X, mu = out.X, out.penalty
            path = wrap_to_pi(X, self.cont)
            path[0] = self.q0
            self.extra.update(
                waypoints=len(path),
                refines=refine,
                penalty=mu,
                d_min_m=out.d_min_m,
                optimised=True,
                smoothness=out.smooth,
                roughness=roughness(path, self.cont),
            )
            checked = self.recheck(path)
            if isinstance(checked, PlanResult):
                return checked
            self.extra["refined_edges"].append(checked)
            X = _split(X, checked)
            self.extra["refines_tried"] = self.extra.get("refines_tried", 0) + 1
        return f"the re-check refused the path after {s.max_refines} refinements"

    def recheck(self, path: Array) -> PlanResult | list[int]:
        """The path re-checked at ``joint_step / 4`` on the grid within the budget and
        the time limit (each + 1 %): solved, the budget's result, or the edges that fail
        (the first one ``check_path`` finds, then every later edge with an invalid grid
        state: at most the grid's states in all, as a passing re-check)."""
        checker, tracker = self.checker, self.tracker
        self.extra["path_length_rad"] = path_length(path, self.cont)
        cost = int(checker.grid_states(path, self.step))
        b = tracker.budget
        if b.max_collision_checks is not None:
            left = b.max_collision_checks + b.max_collision_checks // 100 - tracker.checks_used
            if cost > left:
                return self.result(
                    Status.BUDGET_EXHAUSTED,
                    f"{self.planner.name} found a path but re-checking it at joint_step/4 "
                    f"needs {cost} collision checks and the budget (+1 %) leaves "
                    f"{max(left, 0)}: the path is not trusted",
                    path,
                )
        tl = b.time_limit_s

        def late() -> bool:
            return tl is not None and tracker.elapsed_s >= tl * (1.0 + SLACK)

        c0 = checker.checks
        check = checker.check_path(path, self.step, stop=late, chunk=RECHECK_CHUNK, mode="grid")
        self.extra["validation_checks"] = (
            self.extra.get("validation_checks", 0) + checker.checks - c0
        )
        if not check.complete:
            return self.result(
                Status.BUDGET_EXHAUSTED,
                f"{self.planner.name} found a path but the time limit ran out before its "
                "re-check at joint_step/4 finished: the path is not trusted",
                path,
            )
        if not check.valid:
            first = int(check.first_invalid_edge or 0)
            c1 = checker.checks
            edges = self._failing_edges_after(path, first, late)
            self.extra["validation_checks"] += checker.checks - c1
            if edges is None:
                return self.result(
                    Status.BUDGET_EXHAUSTED,
                    f"{self.planner.name}: the time limit ran out while re-checking a "
                    "refused path's later edges",
                    path,
                )
            return [first, *edges]
        if not bool(self.goal.contains(self.robot, path[-1])):
            return self.result(
                Status.APPROXIMATE,
                f"{self.planner.name}: the path ends outside the goal region",
                path,
            )
        return self.result(Status.SOLVED, f"{self.planner.name}: optimised path", path)

    def _failing_edges_after(self, path: Array, first: int, late: Any) -> list[int] | None:
        """The edges after ``first`` with an invalid grid state (the re-check's grid),
        None when the time limit ran out; every state looked at is a check."""
        states, owners = self.checker.densify(path, self.step)
        later = np.flatnonzero(owners > first)
        bad: set[int] = set()
        for i in range(0, len(later), RECHECK_CHUNK):
            if late():
                return None
            idx = later[i : i + RECHECK_CHUNK]
            valid = self.checker.valid_batch(states[idx])
            bad.update(int(e) for e in owners[idx[~valid]])
        return sorted(bad)


def _split(X: Array, edges: list[int]) -> Array:
    """X with the edges ``edges`` and their neighbours split in two (midpoints
    inserted)."""
    K = len(X)
    split = {e + d for e in edges for d in (-1, 0, 1) if 0 <= e + d < K - 1}
    rows: list[Array] = []
    for k in range(K):
        rows.append(X[k])
        if k in split:
            rows.append(0.5 * (X[k] + X[k + 1]))
    return np.array(rows)


@dataclass(frozen=True)
class TrajOptPlanner(LegPlanner):
    """A ``trajopt.*`` planner with frozen settings (see the module docstring).

    Attributes:
        seed_planners: the planners of the seeds that are planners' paths, by seed name.
    """

    name: str
    settings: TrajOptSettings
    seed_planners: Mapping[str, Any] = field(default_factory=dict)

    def warm_up(self, problem: Any, leg: int, q_start: Array) -> None:
        """Load (or compile) the kernels before the leg's clock starts: the geometry's,
        and the seed planners'."""
        from plannerlab.planners.trajopt.geometry import warm_up

        warm_up()
        for p in self.seed_planners.values():
            w = getattr(p, "warm_up", None)
            if w is not None:
                w(problem, leg, q_start)

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
        built before the leg's clock starts, as ``native.*`` does."""
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

    def plan(self, ctx: PlanningContext, rng: np.random.Generator) -> PlanResult:
        """Plan the leg of ``ctx`` (see the module docstring)."""
        if ctx.checker is None:
            raise PlannerlabError(f"{self.name}: needs a collision checker")
        s = self.settings.for_robot(ctx.robot)
        return _Solve(self, s, ctx, rng).solve()


#: the registry's trajopt planners: name -> (seeds, summary)
VARIANTS: Mapping[str, tuple[str, str]] = {
    "trajopt.line": (
        "line",
        "trajectory optimisation (smoothness under a collision hinge, Gauss-Newton on the "
        "banded structure) from the straight line to each goal state, random restarts",
    ),
    "trajopt.gradient": (
        "gradient",
        "trajectory optimisation seeded by the paper's gradient descent (then the line "
        "from where it stalls)",
    ),
    "trajopt.rrtconnect": (
        "rrtconnect",
        "trajectory optimisation seeded by native.rrtconnect's path (that path when no "
        "optimisation passes the re-check)",
    ),
    "trajopt.leader": (
        "leader",
        "trajectory optimisation seeded by native.rrtconnect+leader's path (that path when "
        "no optimisation passes the re-check)",
    ),
    "trajopt.line+rrtconnect": (
        "line,rrtconnect",
        "trajopt.line, then trajopt.rrtconnect when no line seed gives a path",
    ),
}


def make(name: str, overrides: Mapping[str, Any] | None = None) -> TrajOptPlanner:
    """Registry factory of the ``trajopt.*`` planners; a seed planner's settings are
    overridden as ``<seed>.<key>`` (``rrtconnect.range_rad=0.5``)."""
    if name not in VARIANTS:
        raise PlannerlabError(f"{name} is not a trajopt planner ({', '.join(VARIANTS)})")
    over = dict(overrides or {})
    seed_over: dict[str, dict[str, Any]] = {}
    own: dict[str, Any] = {}
    for k, v in over.items():
        head, dot, rest = k.partition(".")
        if dot and head in ("gradient", "rrtconnect", "leader"):
            seed_over.setdefault(head, {})[rest] = v
        else:
            own[k] = v
    settings = with_overrides(TrajOptSettings(seeds=VARIANTS[name][0]), own, name)
    settings.check(name)
    planners: dict[str, Any] = {}
    for seed in settings.seed_list:
        if seed == "rrtconnect":
            from plannerlab.planners.native import make as make_native

            planners[seed] = make_native("native.rrtconnect", seed_over.get(seed, {}))
        elif seed == "leader":
            from plannerlab.planners.native.leader import make as make_leader

            planners[seed] = make_leader("native.rrtconnect+leader", seed_over.get(seed, {}))
        elif seed == "gradient":
            from plannerlab.planners.gradient import make as make_gradient

            planners[seed] = make_gradient("gradient.analytic", seed_over.get(seed, {}))
    return TrajOptPlanner(name=name, settings=settings, seed_planners=planners)
