"""Seed paths of the trajectory optimiser, and their restarts.

A seed is a joint-space path from the leg's start (continuous joints unwrapped: each step
the short way round), resampled to K waypoints at equal motion (:func:`resample`):

* ``line``: the straight line to each goal state (the joint goal, or the goal pool's IK
  states for a tip region: :func:`~plannerlab.planners.goal_pool.fill_goal_pool`);
* ``gradient``: the paper's gradient descent (``gradient.analytic``: its iterates with the
  analytic gradient) from the start, then, if it stalls outside the goal, the line from
  where it stopped to the nearest goal state;
* ``rrtconnect``, ``leader``: the path of ``native.rrtconnect`` /
  ``native.rrtconnect+leader``, re-checked by them.

The seed planners run as sub-solves in the leg's context (``ctx.sub``: the same checker,
a child tracker with ``seed_share`` of what the leg has left, all of it by default; their
iterations are the leg's). A restart bends a seed by a smooth random bump drawn from the
trial's generator (:func:`bumped`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from plannerlab.planners.base import PlanResult, Status
from plannerlab.planners.context import PlanningContext, plan_in
from plannerlab.problem.goals import JointGoal
from plannerlab.problem.load import Budget
from plannerlab.robots.base import Array, joint_difference, wrap_to_pi

__all__ = ["Seed", "bumped", "goal_states", "planner_seed", "resample", "unwrapped"]


@dataclass(frozen=True)
class Seed:
    """One seed: its name, the path (m, dof, unwrapped) and, when a planner gave it, that
    planner's result (its path re-checked: the fallback when no optimisation works)."""

    name: str
    path: Array
    result: PlanResult | None = None


def unwrapped(path: Array, continuous: NDArray[np.bool_], q0: Array | None = None) -> Array:
    """The path with continuous joints unwrapped (each step the short way round), from
    ``q0`` (default: its first state)."""
    P = np.atleast_2d(np.asarray(path, dtype=float))
    steps = joint_difference(P[1:], P[:-1], continuous)
    start = P[0] if q0 is None else np.asarray(q0, dtype=float)
    return np.vstack([start, start + np.cumsum(steps, axis=0)])


def motion(path: Array, reach: Array) -> Array:
    """Per edge of a path (m, dof), how far any point of the robot can move on it:
    ``Σ_i |Δq_i| · reach_i`` (m − 1,) [m]."""
    return np.abs(np.diff(path, axis=0)) @ np.asarray(reach, dtype=float)


def resample(path: Array, reach: Array, spacing_m: float, k_min: int, k_max: int) -> Array:
    """The path (unwrapped) at K waypoints of equal motion (:func:`motion`) along it,
    ``K = clip(ceil(motion / spacing_m) + 1, k_min, k_max)``, the first and last states
    kept."""
    P = np.atleast_2d(np.asarray(path, dtype=float))
    seg = motion(P, reach) if len(P) > 1 else np.zeros(0)
    keep = np.concatenate([[True], seg > 1e-12])
    P, seg = P[keep], seg[seg > 1e-12]
    total = float(seg.sum())
    K = int(np.clip(math.ceil(total / spacing_m) + 1, k_min, k_max))
    if len(P) == 1:
        return np.repeat(P, K, axis=0)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    t = np.linspace(0.0, total, K)
    out = np.column_stack([np.interp(t, s, P[:, j]) for j in range(P.shape[1])])
    out[0], out[-1] = P[0], P[-1]
    return out


def bumped(
    X: Array, rng: np.random.Generator, sigma_rad: float, lower: Array, upper: Array
) -> Array:
    """X (K, dof) bent by a smooth random bump: per joint a normal deviate of ``sigma_rad``
    times ``sin(π s)`` (s from 0 at the start to 1 at the end), the ends kept, joint
    limits held."""
    K = len(X)
    arch = np.sin(np.pi * np.linspace(0.0, 1.0, K))[:, None]
    bump = np.asarray(rng.normal(0.0, sigma_rad, size=X.shape[1]), dtype=float)
    Y = X + arch * bump[None, :]
    Y[0], Y[-1] = X[0], X[-1]
    return np.clip(Y, lower, upper)


def goal_states(
    ctx: PlanningContext,
    settings: Any,
    rng: np.random.Generator,
    q0: Array,
    extra: dict[str, Any],
    guard: Any,
) -> tuple[list[Array], str]:
    """The leg's goal states: the joint goal's, or the goal pool's (IK; within the
    budget, ``guard`` as :func:`~plannerlab.planners.goal_pool.fill_goal_pool` wants it),
    each unwrapped next to ``q0``; and why the pool was cut short ("" if not)."""
    cont = np.asarray(ctx.robot.continuous, dtype=bool)
    goal = ctx.goal
    if isinstance(goal, JointGoal):
        q_goal = wrap_to_pi(np.asarray(goal.q_rad, dtype=float), cont)
        return [q0 + joint_difference(q_goal, q0, cont)], ""
    from plannerlab.planners.goal_pool import fill_goal_pool

    pool, cut = fill_goal_pool(ctx, settings, guard, rng, q0, extra)
    return [q0 + joint_difference(g, q0, cont) for g in pool], cut


def _share(ctx: PlanningContext, share: float) -> Budget | None:
    """``share`` of the collision checks and time the leg has left (its iterations
    all), or None when a limit is used up."""
    left = ctx.tracker.remaining()
    if left is None:
        return None
    checks = left.max_collision_checks
    time_s = left.time_limit_s
    return Budget(
        max_iterations=left.max_iterations,
        max_collision_checks=None if checks is None else max(int(checks * share), 1),
        time_limit_s=None if time_s is None else time_s * share,
        clock=left.clock,
    )


def planner_seed(
    name: str, planner: Any, ctx: PlanningContext, rng: np.random.Generator, q0: Array, share: float
) -> tuple[Seed | None, PlanResult | None]:
    """A seed planner's path as a seed (None when it found no path), and its result
    (None when the leg's budget left nothing to run it with). Its iterations are charged
    to the leg's tracker."""
    budget = _share(ctx, share)
    if budget is None:
        return None, None
    r = plan_in(planner, ctx.sub(budget, q0), rng)
    ctx.tracker.charge(r, checks=False)
    cont = np.asarray(ctx.robot.continuous, dtype=bool)
    if r.status is Status.SOLVED:
        return Seed(name, unwrapped(r.path, cont, q0), r), r
    if name == "gradient" and len(r.path) > 1:
        return Seed(name, unwrapped(r.path, cont, q0)), r
    return None, r
