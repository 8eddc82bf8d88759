"""Numeric inverse kinematics for any :class:`~plannerlab.robots.base.Robot`.

Damped least squares (Levenberg-Marquardt style) on the tip position error [m] and the
tip normal error (unit vectors), using the robot's analytic ``tip_jacobian``. Both errors
are scaled by the goal's tolerances (position by ``pos_tol_m``, normal by the angle
tolerance in radians), so one unit of scaled error is "one tolerance" in either term and
neither dominates. Bounded joints are clipped to ``[lower, upper]``; continuous joints are
wrapped into ``[-pi, pi)``.

:func:`solve_ik` is one local descent from one seed. :func:`sample_goal_state` restarts it
until it finds a collision-free state inside both tolerances; it is what goal-sampling
planners (OMPL's ``GoalSampleableRegion`` in :mod:`plannerlab.planners.ompl`) call.

Only numpy is used here; a collision checker is passed in (anything with
``is_valid(q) -> bool``), never imported.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from plannerlab.problem.goals import GoalRegion, JointGoal
from plannerlab.robots.base import Array, Robot, wrap_to_pi
from plannerlab.robots.registry import goal_sampler


class ValidityChecker(Protocol):
    """What IK needs from a collision checker."""

    def is_valid(self, q: Array) -> bool: ...


@dataclass(frozen=True)
class IKResult:
    """Outcome of one IK descent.

    Attributes:
        q: (dof,) final joint state (continuous joints wrapped, bounded ones clipped).
        success: q is inside both tolerances (and collision-free if a checker was given).
        iterations: descent steps taken.
        reason: why it stopped, in words.
        pos_err_m: final tip position error [m].
        angle_err_deg: final tip normal error [deg].
    """

    q: Array
    success: bool
    iterations: int
    reason: str
    pos_err_m: float
    angle_err_deg: float


#: IK results are rounded to this many decimals [rad or m] (see :func:`solve_ik`)
_ROUND_DECIMALS = 9


def _clamp(robot: Robot, q: Array) -> Array:
    """Clip bounded joints into their limits and wrap continuous ones into [-pi, pi)."""
    q = np.where(robot.continuous, q, np.clip(q, robot.lower, robot.upper))
    return wrap_to_pi(q, robot.continuous)


def solve_ik(
    robot: Robot,
    goal: GoalRegion,
    q_seed: Array,
    rng: np.random.Generator | None = None,
    checker: ValidityChecker | None = None,
    max_iterations: int = 150,
    damping: float = 0.05,
    max_step_rad: float = 0.25,
    target_fraction: float = 0.3,
    descent: Callable[..., tuple[Array, int]] | None = None,
) -> IKResult:
    """One damped-least-squares descent from ``q_seed`` towards the goal region.

    The scaled error ``e = [(p_d - p) / pos_tol, (n_d - n) / angle_tol_rad]`` (6,) is driven
    down by ``dq = J^T (J J^T + damping^2 I)^-1 e`` with ``J`` the Jacobian of ``[p / pos_tol,
    n / angle_tol_rad]``; each step is scaled so that no joint moves more than
    ``max_step_rad``. The descent aims at ``target_fraction`` of the tolerances (deeper
    than needed, so the result is robustly inside) and stops early once there.

    A robot family with an analytic IK registers its sampler
    (:attr:`plannerlab.robots.registry.RobotFamily.goal_sampler`)
    (``sampler(robot, goal, rng, seeds)``: a state inside the region, collision ignored,
    or None); it is used instead of the numeric descent, and each candidate is
    collision-checked here.

    Args:
        robot: any joint-vector robot.
        goal: target position + normal with tolerances.
        q_seed: (dof,) initial state.
        rng: unused by the descent itself (it is deterministic); accepted so that all IK
            entry points share one signature.
        checker: if given, the final state must also be collision-free (one check).
        max_iterations: descent steps at most.
        damping: damping factor λ of the least-squares step (in scaled-error units).
        max_step_rad: largest joint change per step [rad or m].
        target_fraction: stop once both scaled errors are below this fraction of the
            tolerances.
        descent: the same descent compiled for this robot
            (:func:`plannerlab.collision.chain_ik.descent_for_robot`), called as
            ``descent(goal, q_seed, max_iterations, damping, max_step_rad,
            target_fraction) -> (q, steps)``; None: in numpy.

    Returns:
        An :class:`IKResult`; ``success`` is False with a reason when the descent ends
        outside the region or in collision.
    """
    del rng  # deterministic descent
    if descent is not None:
        q, iterations = descent(
            goal, q_seed, max_iterations, damping, max_step_rad, target_fraction
        )
        return _verdict(robot, goal, q, iterations, checker)
    q = _clamp(robot, np.asarray(q_seed, dtype=float).reshape(robot.dof))
    pos_scale = 1.0 / goal.pos_tol_m
    ang_scale = 1.0 / np.deg2rad(goal.angle_tol_deg)
    lam2 = damping**2
    iterations = 0
    # a robot that gives tip and Jacobian from one forward kinematics (the same numbers)
    both = getattr(robot, "tip_and_jacobian", None)
    for iterations in range(1, max_iterations + 1):  # noqa: B007 - count survives the loop
        if both is not None:
            p, n, J_p, J_n = both(q)
        else:
            p, n = robot.tip(q)
        pos_e, ang_e = goal.errors_from_tip(p, n)
        if (
            pos_e <= target_fraction * goal.pos_tol_m
            and ang_e <= target_fraction * goal.angle_tol_deg
        ):
            iterations -= 1
            break
        e = np.concatenate([(goal.p_world_m - p) * pos_scale, (goal.n_world - n) * ang_scale])
        if both is None:
            J_p, J_n = robot.tip_jacobian(q)
        J = np.vstack([J_p * pos_scale, J_n * ang_scale])  # (6, dof)
        dq = J.T @ np.linalg.solve(J @ J.T + lam2 * np.eye(6), e)
        biggest = float(np.max(np.abs(dq), initial=0.0))
        if biggest > max_step_rad:
            dq *= max_step_rad / biggest
        q = _clamp(robot, q + dq)
    return _verdict(robot, goal, q, iterations, checker)


def _verdict(
    robot: Robot, goal: GoalRegion, q: Array, iterations: int, checker: ValidityChecker | None
) -> IKResult:
    """A descent's end state judged: inside both tolerances (numpy), then collision-free."""
    # rounded to 1e-9 rad: the descent's linear algebra differs in its last bits between
    # CPUs (BLAS kernels), and a goal state that differs by 1e-16 sends a seeded planner
    # down another road; the rounded state is the one tested and returned
    q = _clamp(robot, np.round(q, _ROUND_DECIMALS) + 0.0)
    pos_err, ang_err = (float(v) for v in goal.errors(robot, q))
    inside = pos_err <= goal.pos_tol_m and ang_err <= goal.angle_tol_deg
    if not inside:
        return IKResult(
            q,
            False,
            iterations,
            f"ended outside the region after {iterations} steps "
            f"({pos_err:.3g} m, {ang_err:.3g} deg)",
            pos_err,
            ang_err,
        )
    if checker is not None and not checker.is_valid(q):
        return IKResult(
            q, False, iterations, "reached the region but the state collides", pos_err, ang_err
        )
    return IKResult(q, True, iterations, "inside both tolerances", pos_err, ang_err)


def _analytic_goal_sampler(robot: Any) -> Any:
    """The robot family's analytic goal sampler (:mod:`plannerlab.robots.registry`)."""
    return goal_sampler(getattr(robot, "kind", ""))


def sample_goal_state(
    robot: Robot,
    goal: GoalRegion,
    checker: ValidityChecker,
    rng: np.random.Generator,
    seeds: Sequence[Array] = (),
    attempts: int = 40,
    noise_start_rad: float = 0.02,
    noise_growth: float = 1.35,
    uniform_fraction: float = 0.5,
    max_iterations: int = 150,
    stop: Callable[[], bool] | None = None,
    descent: Any = None,
) -> Array | None:
    """A collision-free state inside both tolerances of ``goal``, or None.

    A :class:`~plannerlab.problem.goals.JointGoal` is its goal state (if it is valid).

    Restart schedule, attempt ``k = 0, 1, …``: with probability ``uniform_fraction`` (never
    on the first attempt of each seed round when seeds are given) a uniformly random state;
    otherwise seed ``k mod len(seeds)`` plus Gaussian noise of standard deviation
    ``noise_start_rad * noise_growth ** k`` (capped at pi), so the first restarts stay in
    the seed's homotopy class and later ones explore further. Each start is refined by
    :func:`solve_ik`; the first valid result is returned.

    Measured on ``armz_inspection`` (23 joints, a room entered through a window; per
    descent ~2-4 ms, one collision check): the descent almost always *reaches* the region
    (40/40 from every kind of start), but the state it reaches usually collides, so the
    success rate per attempt is the collision-free rate. ``enter`` from the rest pose is
    found in the first 1-10 attempts. For A-E, uniform restarts succeed in ~0-5 % of
    attempts (A 1/40, B 2/40, C 0/40, D 1/40, E 1/40), seeds from the rest pose ~0-2 %;
    seeds from an ``enter`` state (the leg start of A) + 0.1 rad noise did well only for
    some goals (B 33/40, A/C/D/E 0/40 with that seed) and depend strongly on which
    ``enter`` state it is. Hence the mixed schedule (seeds first, then half seeds with
    growing noise and half uniform restarts) and the caller should give it the leg start
    *and* any previously found goal states as seeds. The papers.md remark holds in spirit:
    plain IK is not enough for A-E; a collision-aware (null-space) repair is what is
    missing here.

    A robot family with an analytic IK registers its sampler
    (:attr:`plannerlab.robots.registry.RobotFamily.goal_sampler`)
    (``sampler(robot, goal, rng, seeds)``: a state inside the region, collision ignored,
    or None); it is used instead of the numeric descent, and each candidate is
    collision-checked here.

    Args:
        robot: any joint-vector robot.
        goal: the goal region.
        checker: collision checker (``is_valid``); every candidate costs one check.
        rng: random generator for the noise and the uniform restarts.
        seeds: states to restart from (e.g. the leg's start); may be empty.
        attempts: IK descents at most.
        noise_start_rad, noise_growth: noise schedule around the seeds [rad].
        uniform_fraction: share of restarts from uniformly random states.
        max_iterations: descent steps per attempt.
        stop: asked before each attempt (a time limit, say); True ends the search (None).
        descent: the robot's IK descent compiled, restarted instead of the numpy one
            (:func:`plannerlab.collision.chain_ik.descent_for_robot`: URDF chains, which
            the planners' goal sampling passes; ``bench/model_bench.py --ik``); None: the
            numpy descent. The restarts, the region test and the collision check are the
            same either way.

    Returns:
        (dof,) state inside the region and collision-free, or None after ``attempts``
        (or once ``stop`` says so).
    """
    if isinstance(goal, JointGoal):
        # a goal state is its own (only) sample: one check
        if stop is not None and stop():
            return None
        return np.array(goal.q_rad) if checker.is_valid(goal.q_rad) else None
    seed_list = [np.asarray(s, dtype=float).reshape(robot.dof) for s in seeds]
    analytic = _analytic_goal_sampler(robot)
    if analytic is not None:
        # Robots with analytic IK (the IRb-6) sample the region themselves; each candidate
        # still costs one collision check here.
        for _ in range(attempts):
            if stop is not None and stop():
                return None
            q = analytic(robot, goal, rng, seeds=seed_list or None)
            if q is not None and checker.is_valid(q):
                return np.asarray(q, dtype=float)
        return None
    for k in range(attempts):
        if stop is not None and stop():
            return None
        use_uniform = not seed_list or (k >= len(seed_list) and rng.random() < uniform_fraction)
        if use_uniform:
            q0 = rng.uniform(robot.lower, robot.upper)
        else:
            sigma = min(noise_start_rad * noise_growth**k, np.pi)
            q0 = seed_list[k % len(seed_list)] + rng.normal(0.0, sigma, robot.dof)
        result = solve_ik(
            robot, goal, q0, checker=checker, max_iterations=max_iterations, descent=descent
        )
        if result.success:
            return result.q
    return None


__all__ = ["IKResult", "ValidityChecker", "sample_goal_state", "solve_ik"]
