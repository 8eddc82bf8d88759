"""Running a planner over the legs of a problem, the plan file it produces, and executing it.

A *task* is every leg of a problem in order; leg ``i`` starts where leg ``i − 1``'s path
ended (the planned end, or the executed end for closed-loop planners, which execute as
they plan). :func:`solve_legs` returns a :class:`~plannerlab.record.plan.Plan`, the record
that plan files hold.

One plan, one verdict: a leg's path has one canonical form, its waypoints
(:func:`~plannerlab.robots.paths.waypoints`, states inside a straight joint-space segment
left out; a fixed point). :func:`solve_legs` returns every leg in that form, a plan file
holds exactly it (JSON writes a float's shortest repr, which reads back bit for bit), and
:func:`execute_results`, the one road every execution takes (``compare --execute``,
``plannerlab execute``, :func:`plannerlab.execute`, ``animate``), runs it. (Files used to
hold waypoints while ``compare`` executed the planner's own states. Executing densifies
each edge on its own, to a whole number of re-check steps, so a straight run of descent
steps of shrinking length, 6 × 0.01 + 0.005 + 0.0019 + 0.0014 rad, was 15 re-check
intervals and the one segment it collapses to 14, at other states: the re-check states
and the retimed spline's knots differed, and so did what PyBullet did.)
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from contextlib import ExitStack
from pathlib import Path
from typing import Any

import numpy as np

from plannerlab.errors import PlanFileError, PlannerlabError, ProblemError
from plannerlab.planners import get_entry, make_planner
from plannerlab.planners.base import LegRun, planned_clearance_m, start_collision
from plannerlab.planners.context import PlanningContext
from plannerlab.problem.goals import unreachable_reason
from plannerlab.problem.load import Budget, Problem
from plannerlab.record.execution import Execution
from plannerlab.record.files import versions
from plannerlab.record.leg import PlanResult, Status
from plannerlab.record.plan import Plan, file_sha256
from plannerlab.robots.paths import edge_counts, roughness, waypoints

#: most grid states measured in one compiled call (a long path is measured in pieces of
#: whole edges, so its grid never has to fit in memory at once)
CLEARANCE_CHUNK = 8192


class SharedChecker:
    """A problem's collision checker (``problem_checker``: its clearance margin), built on
    first use and then the same object for every caller: one per trial, shared by its
    solve and its execution's re-check (and so one compiled robot–scene model)."""

    def __init__(self, problem: Problem) -> None:
        self.problem = problem
        self._checker: Any = None

    def get(self) -> Any:
        """The checker (built now if it was not)."""
        if self._checker is None:
            from plannerlab.collision.fcl_checker import problem_checker

            self._checker = problem_checker(self.problem)
        return self._checker


def canonical_result(r: PlanResult) -> PlanResult:
    """``r`` with its path in the canonical form every road executes and plan files hold:
    its waypoints (``r`` itself when nothing drops)."""
    path = waypoints(r.path)
    return r if len(path) == len(r.path) else r.replace(path=path)


def path_clearance_m(checker: Any, path: np.ndarray, joint_step: float) -> float:
    """Smallest clearance [m] along the whole of ``path``: every state of the grid the final
    re-check checks (``checker.densify`` at ``joint_step``), true capsules (the checker's
    margin added back), to the scene and between checked link pairs, in compiled calls of
    at most :data:`CLEARANCE_CHUNK` states. Not counted as collision checks (a measurement
    of the result)."""
    P = np.atleast_2d(np.asarray(path, dtype=float))
    if len(P) < 2:
        return planned_clearance_m(checker, P)
    _, n = edge_counts(P, joint_step, checker.robot.continuous, checker.edge_weights)
    best, start, count = np.inf, 0, 0
    for i, k in enumerate(n):
        count += int(k)
        if count >= CLEARANCE_CHUNK or i == len(n) - 1:
            dense, _ = checker.densify(P[start : i + 2], joint_step)
            best = min(best, planned_clearance_m(checker, dense))
            start, count = i + 1, 0
    return float(best)


def measured(problem: Problem, r: PlanResult, checker: Any | None) -> PlanResult:
    """``r`` with its goal's tolerances and, when it solved, its path's quality: roughness
    (:func:`~plannerlab.robots.paths.roughness`) and the smallest clearance along the
    whole path (:func:`path_clearance_m` at the final re-check's ``joint_step / 4``; not
    for a contact plan, which touches by design, nor without a checker). Measured after
    the solve: outside the planner's clock and its counts."""
    goal = problem.goal(r.leg)
    changes: dict[str, Any] = {"pos_tol_m": goal.pos_tol_m, "angle_tol_deg": goal.angle_tol_deg}
    if r.solved:
        changes["roughness_rad2"] = roughness(r.path, problem.robot.continuous)
        if checker is not None and r.contact_plan is None and hasattr(checker, "densify"):
            changes["path_clearance_m"] = path_clearance_m(
                checker, r.path, problem.joint_step / 4.0
            )
    return r.replace(**changes)


def leg_rng(seed: int, leg: int) -> np.random.Generator:
    """The generator of one leg of one trial: independent streams per (seed, leg)."""
    return np.random.default_rng(np.random.SeedSequence([int(seed), int(leg)]))


def _unreachable(
    problem: Problem, planner_name: str, leg: int, why: str, q_start: np.ndarray | None
) -> PlanResult:
    """The result of a leg whose goal is out of reach: not planned, the path stays put."""
    q = problem.q_start if q_start is None else np.asarray(q_start, dtype=float)
    # no settings, no budget tracker: no time, checks or progress
    return LegRun(planner_name, None, problem, leg).result(Status.UNREACHABLE, why, [q])


#: the problem's start was not checked with the clearance margin (see _refuse_colliding_start)
_UNCHECKED = "not checked"


def _refuse_colliding_start(problem: Problem, with_margin: str | None) -> None:
    """Raise a ProblemError naming the colliding pairs if the problem's start state
    collides (without the clearance margin: bad input, not a planning failure).

    ``with_margin`` is the first leg's start-state check (the context's, with the margin):
    None, a free start, settles it with no other check; a start within the margin, or one
    not checked (``_UNCHECKED``: a contact-permitting planner's leg, an unreachable one),
    is checked here without the margin."""
    if with_margin is None:
        return
    from plannerlab.collision.fcl_checker import CollisionChecker

    reason = start_collision(CollisionChecker(problem.robot, problem.scene), problem.q_start)
    if reason is not None:
        raise ProblemError(problem.source, "start", f"a collision-free start state; {reason}")


def legs_from_spec(problem: Problem, spec: str | None) -> list[int] | None:
    """The legs a ``--legs`` text names (indices or goal names, comma-separated; ``all`` or
    None: every leg).

    Raises:
        PlannerlabError: an unknown leg (the problem's legs listed) or one named twice.
    """
    if spec is None or spec.strip() == "all":
        return None
    legs = []
    for x in spec.split(","):
        x = x.strip()
        try:
            legs.append(problem.resolve_leg(x))
        except (IndexError, KeyError) as exc:
            names = ", ".join(f"{i} {g.name}" for i, g in enumerate(problem.goals))
            raise PlannerlabError(
                f"--legs: unknown leg {x!r} of {problem.name} ({problem.source}); "
                f"its legs are: {names}"
            ) from exc
    if len(set(legs)) != len(legs):
        raise PlannerlabError(f"--legs: {spec!r} names a leg twice")
    return legs


def resolve_legs(problem: Problem, legs: str | int | Sequence[int | str] | None) -> list[int]:
    """The legs ``legs`` names, as the command line's ``--legs`` takes them: None or
    ``"all"`` (every leg), a leg (its index or its goal's name: ``"home"``), a
    comma-separated text (``"enter,A"``), or a sequence of indices and names.

    Raises:
        PlannerlabError: an unknown leg (the problem's legs listed) or one named twice.
    """
    if legs is None:
        return list(range(problem.legs))
    if isinstance(legs, str):
        named = legs_from_spec(problem, legs)
        return list(range(problem.legs)) if named is None else named
    if isinstance(legs, int | np.integer):
        legs = [int(legs)]
    if not legs:
        return []
    return legs_from_spec(problem, ",".join(str(x) for x in legs)) or []


def solve_legs(
    problem: Problem,
    planner_name: str,
    seed: int,
    *,
    legs: str | int | Sequence[int | str] | None = None,
    budget: Budget | None = None,
    overrides: dict[str, Any] | None = None,
    stop_on_failure: bool = False,
    gui: bool = False,
    on_leg: Callable[[PlanResult], None] | None = None,
    shared: SharedChecker | None = None,
    planner: Any = None,
) -> Plan:
    """Solve ``legs`` (default: all) in order; each starts where the previous one ended.

    ``legs`` names legs by index or by goal name, as ``--legs`` does (:func:`resolve_legs`:
    ``legs="home"``, ``legs=["enter", 2]``, ``legs="enter,A"``).

    One collision checker serves the problem (with its clearance margin); each leg gets
    one :class:`~plannerlab.planners.context.PlanningContext` (its start checked once, its
    budget tracker) that the planner and its sub-solves plan in. A problem whose own start
    state collides is refused (ProblemError). Closed-loop planners get one PyBullet world
    for the whole task. Every leg's path comes back in its canonical form
    (:func:`canonical_result`): the plan in memory is the plan its file holds.

    ``shared``: the problem's checker built once and shared (with its compiled model) with
    the execution's re-check (:func:`execute_results`) of the same trial; None: built
    here when a leg needs it. ``planner``: ``planner_name`` already built with
    ``overrides`` (a comparison builds it once to check the settings); None: built here.
    """
    entry = get_entry(planner_name)
    if planner is None:
        planner = make_planner(planner_name, overrides)
    shared = shared or SharedChecker(problem)  # built on first use, then the same
    budget = budget or problem.budget
    legs = resolve_legs(problem, legs)
    results: list[PlanResult] = []
    checker = None
    if legs and hasattr(planner, "plan") and not getattr(planner, "allows_contact", False):
        # one per problem: every leg's context shares it
        checker = shared.get()
    with ExitStack() as stack:
        stepper = None
        if entry.needs_stepper:
            from plannerlab.sim import SimWorld

            stepper = stack.enter_context(
                SimWorld(
                    problem.robot,
                    problem.scene,
                    gui=gui,
                    gravity_mps2=problem.simulation.gravity_mps2,
                )
            )
        q = None  # the first leg starts at the problem's start state
        for leg in legs:
            first = not results  # it starts at the problem's start state
            why = unreachable_reason(problem.robot, problem.goal(leg))
            if why is not None:
                if first:
                    _refuse_colliding_start(problem, _UNCHECKED)
                r = _unreachable(problem, planner_name, leg, why, q)
            elif hasattr(planner, "plan"):  # a LegPlanner: it plans in the leg's context
                ctx = PlanningContext.for_planner(
                    planner, problem, leg, budget, q_start=q, checker=checker, stepper=stepper
                )
                if first:
                    _refuse_colliding_start(
                        problem, ctx.start_problem if ctx.start_checked else _UNCHECKED
                    )
                r = planner.plan(ctx, leg_rng(seed, leg))
            else:  # a planner of the contract's call only (docs/extending.md)
                if first:
                    _refuse_colliding_start(problem, _UNCHECKED)
                r = planner.solve(
                    problem, leg, budget, leg_rng(seed, leg), q_start=q, stepper=stepper
                )
            r = canonical_result(r.replace(seed=seed))
            meter = checker
            if r.solved and meter is None and r.contact_plan is None:
                meter = shared.get()  # the problem's one checker, to measure the path
            r = measured(problem, r, meter)
            results.append(r)
            if on_leg is not None:
                on_leg(r)
            q = r.path[-1]
            if stop_on_failure and r.status is not Status.SOLVED:
                break
    # resolved: the plan finds its problem from any working directory
    problem_file = Path(problem.source).resolve() if Path(problem.source).is_file() else None
    return Plan(
        problem=problem.name,
        problem_file=str(problem_file) if problem_file else "",
        problem_sha256=file_sha256(problem_file) if problem_file else "",
        planner=planner_name,
        seed=seed,
        budget=budget.to_dict(),
        legs=tuple(results),
        overrides=dict(overrides or {}),
        versions=versions(),
    )


def execute_results(
    problem: Problem,
    results: Sequence[PlanResult],
    *,
    gui: bool = False,
    shared: SharedChecker | None = None,
) -> list[Execution]:
    """Execute planned legs in PyBullet: one :class:`Execution` per leg, in order.

    The one road of every execution. Each leg runs its canonical path
    (:func:`canonical_result`), so results from :func:`solve_legs`, from a plan file or
    straight from a planner execute alike.

    Ordinary legs run in one world, each from where the previous one really ended
    (:func:`plannerlab.sim.execute.execute_legs`). Legs of a contact-permitting planner
    (a leg with a ``contact_plan``: ``chord_arc``, whose paths touch the collision
    points on purpose) run in :func:`plannerlab.sim.continuum.execute_chord_arc`, which sorts
    expected from unexpected contacts; each of them starts from its path's first state.

    ``shared``: the problem's checker to re-check the paths with, shared with the solve
    that planned them (:func:`solve_legs`); None: the executor builds its own.

    Raises:
        PlannerlabError: no legs, or a contact plan's leg without a chosen solution.
    """
    if not results:
        raise PlannerlabError("nothing to execute: the plan has no legs")
    results = [canonical_result(r) for r in results]
    if any(r.contact_plan is not None for r in results):
        from plannerlab.sim.continuum import execute_chord_arc

        return [execute_chord_arc(problem, r, gui=gui) for r in results]
    from plannerlab.sim.execute import execute_legs

    return execute_legs(
        problem,
        [r.path for r in results],
        first_leg=results[0].leg,
        gui=gui,
        checker=None if shared is None else shared.get(),
    )


def execute_plan(
    plan: Plan,
    problem: Problem | None = None,
    *,
    allow_changed_problem: bool = False,
    gui: bool = False,
) -> list[Execution]:
    """Execute every leg of ``plan`` in PyBullet (:func:`execute_results`: in one world,
    each leg from where the previous one really ended; a contact plan's legs in the
    continuum's executor).

    Args:
        plan: what :func:`solve_legs` returned, or :meth:`Plan.load` read.
        problem: the problem it was planned on (default: load ``plan.problem_file``,
            refusing a file that changed since planning unless ``allow_changed_problem``).
            A problem of another name, or whose robot or legs do not fit the plan's, is
            refused.
        gui: a PyBullet window instead of DIRECT.

    Raises:
        PlanFileError: the problem file changed since planning, or ``problem`` is not the
            plan's.
    """
    from plannerlab.run.plan_check import check_plan

    if problem is None:
        changed = plan.problem_changed()
        if changed and not allow_changed_problem:
            raise PlanFileError(f"{plan.problem}: {changed}")
        problem = plan.load_problem()
    elif plan.problem != problem.name:
        raise PlanFileError(
            f"a plan of {plan.problem!r} ({plan.planner}, seed {plan.seed}) cannot be executed "
            f"on {problem.name!r} ({problem.source}): give it its own problem, or none "
            "(execute(plan) loads the problem the plan was made on)"
        )
    check_plan(plan, problem, f"the plan of {plan.problem} ({plan.planner}, seed {plan.seed})")
    return execute_results(problem, plan.legs, gui=gui)
